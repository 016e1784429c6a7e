// The cpu backend's own options (sh::cpu::Options): their string form, and
// what the kernel compiler reads from them.
#include <cstdint>
#include <fstream>

#include <llvm/ADT/StringMap.h>
#include <llvm/ADT/Triple.h>
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

const char* stores_name(Stores s) { return s == Stores::Auto ? "auto" : s == Stores::Cached ? "cached" : "streamed"; }

Stores parse_stores(const std::string& s) {
  for (Stores k : {Stores::Auto, Stores::Cached, Stores::Streamed})
    if (s == stores_name(k)) return k;
  throw Error("cpu backend: setting \"stores\" is \"" + s + "\"; expected auto, cached or streamed");
}

// The size of a cache of this CPU's highest level, as Linux describes it
// (sysconf's figure can be the whole package's), or 0.
std::size_t last_level_cache_bytes() {
  std::size_t found = 0;
  int highest = 0;
  for (int i = 0; i < 8; ++i) {
    std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
    std::ifstream level(dir + "level"), size(dir + "size");
    int l = 0;
    std::size_t kib = 0;
    std::string unit;
    if (!(level >> l) || !(size >> kib >> unit) || unit != "K" || l < highest) continue;
    highest = l;
    found = kib * 1024;
  }
  return found;
}

}  // namespace

Settings Options::settings() const {
  Settings s;
  if (width != Width::Auto) s["width"] = width_name(width);
  if (tables != Tables::Memory) s["tables"] = "fetched";
  if (stores != Stores::Auto) s["stores"] = stores_name(stores);
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name == "width")
    width = parse_width(value);
  else if (name == "tables")
    tables = parse_tables(value);
  else if (name == "stores")
    stores = parse_stores(value);
  else
    throw Error("the cpu backend has no setting '" + name + "' (width, tables, stores)");
}

std::vector<Backend::Setting> settings() {
  return {{"width", "scalar, 4, 8, 16 or auto: lanes per kernel, auto the host's widest"},
          {"tables", "memory or fetched: fetched reads tables through calls, so they may be TableSources"},
          {"stores", "auto, cached or streamed: streamed writes outputs past the cache, auto a run's that "
                     "together take half the last-level cache or more"}};
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

bool may_stream(const sh::Options& options) {
  return options.get<Options>().stores != Stores::Cached && lane_count(options) > 1 &&
         llvm::Triple(llvm::sys::getProcessTriple()).isX86();
}

std::size_t streamed_from_bytes(const sh::Options& options) {
  switch (options.get<Options>().stores) {
    case Stores::Streamed: return 0;
    case Stores::Cached: return SIZE_MAX;
    case Stores::Auto: break;
  }
  // Where Linux does not say, the size of a server's cache of one core
  // complex.
  static const std::size_t half_cache = [] {
    std::size_t bytes = last_level_cache_bytes();
    return (bytes ? bytes : std::size_t{32} << 20) / 2;
  }();
  return half_cache;
}

}  // namespace sh::cpu
