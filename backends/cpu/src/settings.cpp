// The cpu backend's own options (sh::cpu::Options): their string form, and
// what the kernel compiler reads from them.
#include <cstdint>
#include <fstream>
#include <vector>

#include <llvm/ADT/StringMap.h>
#include <llvm/ADT/Triple.h>
#include <llvm/Support/Host.h>

#include "lower.hpp"
#include "sh/cpu.hpp"
#include "sh/error.hpp"

namespace sh::cpu {
namespace {

int widest_lanes(const llvm::StringMap<bool>& features) {
  if (features.lookup("avx512f")) return 16;
  if (features.lookup("avx")) return 8;
  return 4;
}

const char* isa_name(Isa i) {
  switch (i) {
    case Isa::Host: return "host";
    case Isa::Sse42: return "sse4.2";
    case Isa::Avx2: return "avx2";
    case Isa::Avx512: return "avx512";
  }
  return "?";
}

Isa parse_isa(const std::string& name) {
  for (Isa i : {Isa::Host, Isa::Sse42, Isa::Avx2, Isa::Avx512})
    if (name == isa_name(i)) return i;
  throw Error("cpu backend: setting \"isa\" is \"" + name + "\"; expected host, sse4.2, avx2 or avx512");
}

// An x86-64 level's CPU name in LLVM and the features it adds to the
// level below it, in LLVM's names (the psABI's definition of the levels);
// in Isa's order after Host.
struct Level {
  const char* cpu;
  std::vector<const char*> adds;
};

const std::vector<Level>& levels() {
  static const std::vector<Level> all{
      {"x86-64-v2", {"cx16", "crc32", "sahf", "popcnt", "sse3", "sse4.1", "sse4.2", "ssse3"}},
      {"x86-64-v3", {"avx", "avx2", "bmi", "bmi2", "f16c", "fma", "lzcnt", "movbe", "xsave"}},
      {"x86-64-v4", {"avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"}}};
  return all;
}

llvm::StringMap<bool> host_features() {
  llvm::StringMap<bool> features;
  if (!llvm::sys::getHostCPUFeatures(features)) features.clear();
  return features;
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
  if (isa != Isa::Host) s["isa"] = isa_name(isa);
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name == "width")
    width = parse_width(value);
  else if (name == "tables")
    tables = parse_tables(value);
  else if (name == "stores")
    stores = parse_stores(value);
  else if (name == "isa")
    isa = parse_isa(value);
  else
    throw Error("the cpu backend has no setting '" + name + "' (width, tables, stores, isa)");
}

std::vector<Backend::Setting> settings() {
  return {{"width", "scalar, 4, 8, 16 or auto: lanes per kernel, auto the host's widest"},
          {"tables", "memory or fetched: fetched reads tables through calls, so they may be TableSources"},
          {"stores", "auto, cached or streamed: streamed writes outputs past the cache, auto a run's that "
                     "together take half the last-level cache or more"},
          {"isa", "host, sse4.2, avx2 or avx512: the instructions kernels use, the host's or an x86-64 level's "
                  "it has"}};
}

namespace {

// A level's features, each with the rest of its levels below.
llvm::StringMap<bool> level_features(Isa isa) {
  llvm::StringMap<bool> level;
  for (std::size_t k = 0; k < static_cast<std::size_t>(isa); ++k)
    for (const char* feature : levels()[k].adds) level[feature] = true;
  return level;
}

// Why this host cannot run a level's code ("" where it can).
std::string cannot_run(Isa isa) {
  llvm::Triple process(llvm::sys::getProcessTriple());
  if (!process.isX86() || process.isArch32Bit()) return ", an x86-64 level, and this host is " + process.str();
  llvm::StringMap<bool> host = host_features();
  if (host.empty()) return ", and this host's CPU features could not be read";
  std::string missing;
  for (std::size_t k = 0; k < static_cast<std::size_t>(isa); ++k)
    for (const char* feature : levels()[k].adds)
      if (!host.lookup(feature)) missing += std::string(missing.empty() ? "" : ", ") + feature;
  return missing.empty() ? "" : "; this host lacks " + missing;
}

// The options' level, where the host can run it.
Isa runnable_isa(const sh::Options& options) {
  Isa isa = options.get<Options>().isa;
  if (static_cast<std::size_t>(isa) > levels().size())
    throw Error("cpu backend: isa " + std::to_string(static_cast<int>(isa)) + " is none of host, sse4.2, avx2, avx512");
  if (isa == Isa::Host) return isa;
  if (std::string why = cannot_run(isa); !why.empty())
    throw Error(std::string("cpu backend: setting \"isa\" is \"") + isa_name(isa) + "\"" + why);
  return isa;
}

}  // namespace

std::string isa_cpu(const sh::Options& options) {
  Isa isa = runnable_isa(options);
  return isa == Isa::Host ? "" : levels()[static_cast<std::size_t>(isa) - 1].cpu;
}

llvm::StringMap<bool> isa_features(const sh::Options& options) {
  Isa isa = runnable_isa(options);
  return isa == Isa::Host ? host_features() : level_features(isa);
}

bool host_has(Isa isa) { return isa == Isa::Host || cannot_run(isa).empty(); }

int lane_count(const sh::Options& options) {
  switch (options.get<Options>().width) {
    case Width::Auto: return widest_lanes(isa_features(options));
    case Width::Scalar: return 1;
    case Width::Lanes4: return 4;
    case Width::Lanes8: return 8;
    case Width::Lanes16: return 16;
  }
  throw Error("cpu backend: width " + std::to_string(static_cast<int>(options.get<Options>().width)) +
              " is not one of scalar, 4, 8, 16 or auto");
}

bool fetches_tables(const sh::Options& options) { return options.get<Options>().tables == Tables::Fetched; }

// A kernel with loops of its own (a ray's walk, an iteration) spends its
// time in them, not on its stores: streaming them bought the tracer
// nothing measurable and cost its compile a tenth more.
bool kernel_streams(const ir::Program& program, const sh::Options& options) {
  return options.get<Options>().stores != Stores::Cached && lane_count(options) > 1 &&
         llvm::Triple(llvm::sys::getProcessTriple()).isX86() && !program.outputs.empty() &&
         loop_statements(program).empty();
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
