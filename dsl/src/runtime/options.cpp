// Backend options in their string form: which backend owns a setting, and
// the kernel key.
#include <utility>

#include "sh/backend.hpp"
#include "sh/error.hpp"

namespace sh {
namespace {

bool has_setting(const BackendInfo& b, const std::string& name) {
  for (const Backend::Setting& s : b.settings)
    if (s.name == name) return true;
  return false;
}

// Names only: Backend::settings() and `shtrace info` say what each takes.
std::string settings_of(const BackendInfo& b) {
  if (b.settings.empty()) return b.name + " has no settings";
  std::string out = b.name + ": ";
  for (std::size_t i = 0; i < b.settings.size(); ++i) out += (i ? ", " : "") + b.settings[i].name;
  return out;
}

std::string every_setting(const std::vector<BackendInfo>& all) {
  std::string out;
  for (const BackendInfo& b : all)
    if (!b.settings.empty()) out += (out.empty() ? "" : "; ") + settings_of(b);
  return out.empty() ? "no linked backend has settings" : out;
}

// "backend.name" or a name one linked backend has: {backend, name}.
std::pair<std::string, std::string> owner_of(const std::string& setting) {
  std::vector<BackendInfo> all = backends();
  auto dot = setting.find('.');
  if (dot != std::string::npos) {
    std::string backend = setting.substr(0, dot), name = setting.substr(dot + 1);
    for (const BackendInfo& b : all) {
      if (b.name != backend) continue;
      if (!has_setting(b, name))
        throw Error("setting '" + setting + "': the " + backend + " backend has no setting '" + name + "' (" +
                    settings_of(b) + ")");
      return {backend, name};
    }
    std::string names;
    for (const BackendInfo& b : all) names += (names.empty() ? "" : ", ") + b.name;
    throw Error("setting '" + setting + "': no backend '" + backend + "' is linked (linked: " + names + ")");
  }
  std::vector<std::string> owners;
  for (const BackendInfo& b : all)
    if (has_setting(b, setting)) owners.push_back(b.name);
  if (owners.size() == 1) return {owners[0], setting};
  if (owners.empty()) throw Error("no linked backend has a setting '" + setting + "' (" + every_setting(all) + ")");
  std::string which;
  for (const std::string& o : owners) which += (which.empty() ? "" : ", ") + o + "." + setting;
  throw Error("setting '" + setting + "' is ambiguous: write one of " + which);
}

}  // namespace

void BackendOptions::set(const std::string& name, const std::string& value) {
  if (!held_) throw Error("setting '" + name + "': these options belong to no backend");
  held_ = held_->with(name, value);
}

Options& Options::set(BackendOptions options) {
  if (!options.empty()) backends[options.backend()] = std::move(options);
  return *this;
}

Options& Options::set(const std::string& name, const std::string& value) {
  auto [backend, setting] = owner_of(name);
  auto it = backends.find(backend);
  BackendOptions options = it != backends.end() ? it->second : find_backend(backend).default_options();
  options.set(setting, value);
  backends[backend] = std::move(options);
  return *this;
}

std::string Options::key() const {
  std::string k = std::string(precision == Precision::F32 ? "f32" : "f64") + (math == MathMode::Fast ? ",fast" : ",precise") +
                  ",t" + std::to_string(threads) + ",cap" + std::to_string(max_loop_iterations) + (checked ? ",checked" : "") +
                  (optimize ? "" : ",noopt");
  for (const auto& [backend, options] : backends)
    for (const auto& [name, value] : options.settings()) k += "," + backend + "." + name + "=" + value;
  return k;
}

}  // namespace sh
