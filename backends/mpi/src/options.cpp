// sh::mpi::Options in string form, and the checks every run's options get.
#include <climits>

#include "options.hpp"
#include "sh/error.hpp"

namespace sh::mpi {
namespace {

std::uint64_t whole_number(const std::string& name, const std::string& value) {
  try {
    std::size_t used = 0;
    long long n = std::stoll(value, &used);
    if (used == value.size() && n >= 0) return static_cast<std::uint64_t>(n);
  } catch (const std::exception&) {
  }
  throw Error("mpi backend: setting \"" + name + "\" must be a whole number, not '" + value + "'");
}

void check_range(const char* name, std::uint64_t value, std::uint64_t least, std::uint64_t most) {
  if (value < least || value > most)
    throw Error("mpi backend: setting \"" + std::string(name) + "\" must be from " + std::to_string(least) + " to " +
                std::to_string(most) + ", not " + std::to_string(value));
}

}  // namespace

Settings Options::settings() const {
  Settings s;
  const Options defaults;
  if (!local.empty()) s["local"] = local;
  if (schedule != Schedule::Auto) s["schedule"] = schedule == Schedule::Static ? "static" : "dynamic";
  if (chunk != defaults.chunk) s["chunk"] = std::to_string(chunk);
  if (split_tables) s["split_tables"] = std::to_string(*split_tables);
  if (block_bytes != defaults.block_bytes) s["block_bytes"] = std::to_string(block_bytes);
  if (cache_blocks != defaults.cache_blocks) s["cache_blocks"] = std::to_string(cache_blocks);
  return s;
}

void Options::set(const std::string& name, const std::string& value) {
  if (name == "local") {
    local = value;
  } else if (name == "schedule") {
    if (value != "dynamic" && value != "static")
      throw Error("mpi backend: setting \"schedule\" must be dynamic or static, not '" + value + "'");
    schedule = value == "static" ? Schedule::Static : Schedule::Dynamic;
  } else if (name == "chunk") {
    chunk = whole_number(name, value);
    check_range("chunk", chunk, 1, UINT64_MAX);
  } else if (name == "split_tables") {
    split_tables = value == "off" ? std::nullopt : std::optional(whole_number(name, value));
  } else if (name == "block_bytes") {
    block_bytes = whole_number(name, value);
  } else if (name == "cache_blocks") {
    cache_blocks = whole_number(name, value);
  } else {
    throw Error("the mpi backend has no setting '" + name + "' (local, schedule, chunk, split_tables, block_bytes, cache_blocks)");
  }
  check(*this);
}

void check(const Options& o) {
  check_range("block_bytes", o.block_bytes, 1, 1 << 24);  // one MPI_Get moves a block
  check_range("cache_blocks", o.cache_blocks, 1, 1 << 20);
}

std::vector<Backend::Setting> settings() {
  return {{"local", "the backend each rank runs (default: the preferred one linked)"},
          {"schedule", "dynamic (chunks to ranks as they ask) or static (one share per rank)"},
          {"chunk", "elements per chunk of a dynamic schedule (default: 16 chunks per rank)"},
          {"split_tables", "bytes: tables at least this large are split across ranks (default: off)"},
          {"block_bytes", "a split table's blocks, 1 to 2^24 bytes (default 2048)"},
          {"cache_blocks", "blocks in each rank's cache of a split table, 1 to 2^20 (default 64)"}};
}

}  // namespace sh::mpi
