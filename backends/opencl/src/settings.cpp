// The opencl backend's own options (sh::opencl::Options) in string form.
#include "sh/error.hpp"
#include "sh/opencl.hpp"

namespace sh::opencl {

Settings Options::settings() const {
  Settings s;
  if (!device.empty()) s["device"] = device;
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name != "device") throw Error("the opencl backend has no setting '" + name + "' (device)");
  device = value;
}

}  // namespace sh::opencl
