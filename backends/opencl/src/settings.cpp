// The opencl backend's own options (sh::opencl::Options) in string form.
#include "sh/error.hpp"
#include "sh/opencl.hpp"

namespace sh::opencl {

Settings Options::settings() const {
  Settings s;
  if (!device.empty()) s["device"] = device;
  if (lanes != 0) s["lanes"] = lanes == 1 ? "scalar" : std::to_string(lanes);
  if (streams == Streams::Copied) s["streams"] = "copied";
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name == "device") {
    device = value;
  } else if (name == "lanes") {
    if (value == "auto") lanes = 0;
    else if (value == "scalar" || value == "1") lanes = 1;
    else if (value == "2" || value == "4" || value == "8" || value == "16") lanes = std::stoi(value);
    else throw Error("opencl backend: setting \"lanes\" is \"" + value + "\"; expected scalar, 2, 4, 8, 16 or auto");
  } else if (name == "streams") {
    if (value == "auto") streams = Streams::Auto;
    else if (value == "copied") streams = Streams::Copied;
    else throw Error("opencl backend: setting \"streams\" is \"" + value + "\"; expected auto or copied");
  } else {
    throw Error("the opencl backend has no setting '" + name + "' (device, lanes, streams)");
  }
}

}  // namespace sh::opencl
