// sh::mpi::RunDetails: what each rank and each split table's caches did.
#include <algorithm>
#include <cstdio>
#include <cstring>

#include "sh/mpi.hpp"

namespace sh::mpi {
namespace {

void add_part(std::vector<PartStats>& total, const PartStats& p) {
  auto it = std::find_if(total.begin(), total.end(), [&](const PartStats& t) { return t.part == p.part; });
  if (it == total.end()) {
    total.push_back(p);
    return;
  }
  it->elements += p.elements;
  it->chunks += p.chunks;
  it->busy_s += p.busy_s;
  it->idle_s += p.idle_s;
  it->bytes_sent += p.bytes_sent;
  it->bytes_received += p.bytes_received;
  it->waves = std::max(it->waves, p.waves);
  it->resumed += p.resumed;
  it->held_bytes = p.held_bytes;  // a state, not a sum: the later run's
}

void add_cache(std::vector<TableCacheStats>& total, const TableCacheStats& c) {
  auto it = std::find_if(total.begin(), total.end(), [&](const TableCacheStats& t) { return t.table == c.table; });
  if (it == total.end())
    total.push_back(c);
  else
    it->counts += c.counts;
}

}  // namespace

std::unique_ptr<sh::RunDetails> RunDetails::clone() const { return std::make_unique<RunDetails>(*this); }

void RunDetails::add(const sh::RunDetails& more) {
  auto* m = dynamic_cast<const RunDetails*>(&more);
  if (!m) return;
  for (const PartStats& p : m->parts) add_part(parts, p);
  for (const TableCacheStats& c : m->caches) add_cache(caches, c);
}

std::vector<std::string> RunDetails::describe() const {
  std::vector<std::string> lines;
  char line[320];
  for (const PartStats& p : parts) {
    std::snprintf(line, sizeof line, "rank %d computed %zu elements in %zu chunks: busy %.1f ms, idle %.1f ms, %zu bytes sent, %zu received",
                  p.part, p.elements, p.chunks, 1e3 * p.busy_s, 1e3 * p.idle_s, p.bytes_sent, p.bytes_received);
    if (p.held_bytes > 0)
      std::snprintf(line + std::strlen(line), sizeof line - std::strlen(line), ", %zu bytes of tables kept", p.held_bytes);
    lines.push_back(line);
  }
  // A table split but never read through a cache (a lazy octree's, each
  // rank's own) is left out.
  for (const TableCacheStats& c : caches) {
    if (c.counts.reads == 0) continue;
    std::snprintf(line, sizeof line,
                  "split table %-18s %6zu blocks, cache %zu per rank: %9zu reads, hit rate %6.2f %%, %zu from other ranks, "
                  "%.1f ms filling",
                  c.table.c_str(), c.blocks, c.cache_blocks, c.counts.reads, 100 * c.counts.hit_rate(), c.counts.remote_misses,
                  1e3 * c.counts.fill_s);
    lines.push_back(line);
  }
  return lines;
}

}  // namespace sh::mpi
