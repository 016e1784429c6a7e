// The cpu backend's own options (sh::cpu::Options): their string form, and
// what the kernel compiler reads from them.
#include <llvm/ADT/StringMap.h>
#include <llvm/Support/Host.h>

#include "lower.hpp"
#include "sh/cpu.hpp"
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

std::string width_name(Width w) { return w == Width::Auto ? "auto" : w == Width::Scalar ? "scalar" : std::to_string(static_cast<int>(w)); }

Width parse_width(const std::string& w) {
  if (w == "auto") return Width::Auto;
  if (w == "scalar" || w == "1") return Width::Scalar;
  if (w == "4") return Width::Lanes4;
  if (w == "8") return Width::Lanes8;
  if (w == "16") return Width::Lanes16;
  throw Error("cpu backend: setting \"width\" is \"" + w + "\"; expected scalar, 4, 8, 16 or auto");
}

Tables parse_tables(const std::string& t) {
  if (t == "memory") return Tables::Memory;
  if (t == "fetched") return Tables::Fetched;
  throw Error("cpu backend: setting \"tables\" is \"" + t + "\"; expected memory or fetched");
}

}  // namespace

Settings Options::settings() const {
  Settings s;
  if (width != Width::Auto) s["width"] = width_name(width);
  if (tables != Tables::Memory) s["tables"] = "fetched";
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name == "width")
    width = parse_width(value);
  else if (name == "tables")
    tables = parse_tables(value);
  else
    throw Error("the cpu backend has no setting '" + name + "' (width, tables)");
}

std::vector<Backend::Setting> settings() {
  return {{"width", "scalar, 4, 8, 16 or auto: lanes per kernel, auto the host's widest"},
          {"tables", "memory or fetched: fetched reads tables through calls, so they may be TableSources"}};
}

int lane_count(const sh::Options& options) {
  switch (options.get<Options>().width) {
    case Width::Auto: return host_lanes();
    case Width::Scalar: return 1;
    case Width::Lanes4: return 4;
    case Width::Lanes8: return 8;
    case Width::Lanes16: return 16;
  }
  throw Error("cpu backend: width " + std::to_string(static_cast<int>(options.get<Options>().width)) +
              " is not one of scalar, 4, 8, 16 or auto");
}

bool fetches_tables(const sh::Options& options) { return options.get<Options>().tables == Tables::Fetched; }

}  // namespace sh::cpu
