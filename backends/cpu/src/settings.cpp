// The cpu backend's settings, read from Options::settings.
#include <llvm/ADT/StringMap.h>
#include <llvm/Support/Host.h>

#include "lower.hpp"
#include "sh/error.hpp"

namespace sh::cpu {
namespace {

int host_lanes() {
  llvm::StringMap<bool> features;
  if (!llvm::sys::getHostCPUFeatures(features)) return 4;
  if (features.lookup("avx512f")) return 16;
  if (features.lookup("avx")) return 8;
  return 4;
}

}  // namespace

int lane_count(const Options& options) {
  auto it = options.settings.find("width");
  if (it == options.settings.end() || it->second == "auto") return host_lanes();
  const std::string& w = it->second;
  if (w == "scalar" || w == "1") return 1;
  if (w == "4" || w == "8" || w == "16") return std::stoi(w);
  throw Error("cpu backend: setting \"width\" is \"" + w + "\"; expected scalar, 4, 8, 16 or auto");
}

bool fetches_tables(const Options& options) {
  auto it = options.settings.find("tables");
  if (it == options.settings.end() || it->second == "memory") return false;
  if (it->second == "fetched") return true;
  throw Error("cpu backend: setting \"tables\" is \"" + it->second + "\"; expected memory or fetched");
}

}  // namespace sh::cpu
