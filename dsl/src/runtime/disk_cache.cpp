#include "sh/detail/disk_cache.hpp"

#include <elf.h>
#include <link.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sh::detail {
namespace {

std::uint64_t fnv1a(const char* bytes, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(bytes[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// The checksum that ends every cache file: 8 bytes, this host's order.
constexpr std::size_t kChecksumBytes = sizeof(std::uint64_t);

}  // namespace

std::optional<std::string> cache_directory() {
  std::string dir;
  if (const char* set = std::getenv("SH_CACHE_DIR"); set && *set) {
    if (std::string(set) == "off") return std::nullopt;
    dir = set;
  } else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    dir = std::string(xdg) + "/sh";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    dir = std::string(home) + "/.cache/sh";
  } else {
    return std::nullopt;
  }
  std::error_code ignored;
  std::filesystem::create_directories(dir, ignored);
  return dir;
}

std::optional<std::string> cache_path(const std::string& kind, const std::string& key) {
  std::optional<std::string> dir = cache_directory();
  if (!dir) return std::nullopt;
  std::ostringstream name;
  name << *dir << "/" << kind << "-" << std::hex << fnv1a(key.data(), key.size());
  return name.str();
}

void write_cache_file(const std::string& path, const std::string& bytes) {
  // A name of this write's own: two threads (or processes) storing one
  // entry never write one file.
  static std::atomic<unsigned> writes{0};
  std::string tmp = path + ".tmp" + std::to_string(::getpid()) + "." + std::to_string(writes++);
  std::error_code ignored;
  std::ofstream out(tmp, std::ios::binary);
  std::uint64_t checksum = fnv1a(bytes.data(), bytes.size());
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.write(reinterpret_cast<const char*>(&checksum), kChecksumBytes);
  out.close();
  if (!out) {  // a full disk: nothing left behind
    std::filesystem::remove(tmp, ignored);
    return;
  }
  std::filesystem::rename(tmp, path, ignored);
  if (ignored) std::filesystem::remove(tmp, ignored);
}

std::optional<std::string> read_cache_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream read;
  read << in.rdbuf();
  std::string bytes = read.str();
  if (bytes.size() < kChecksumBytes) return std::nullopt;
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, bytes.data() + bytes.size() - kChecksumBytes, kChecksumBytes);
  bytes.resize(bytes.size() - kChecksumBytes);
  if (fnv1a(bytes.data(), bytes.size()) != checksum) return std::nullopt;
  return bytes;
}

namespace {

struct BuildIdSearch {
  std::uintptr_t address;
  std::string id;
};

// The note NT_GNU_BUILD_ID of the loaded object whose segments hold the
// address.
int find_build_id(dl_phdr_info* info, std::size_t, void* data) {
  auto* search = static_cast<BuildIdSearch*>(data);
  bool holds = false;
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[i];
    std::uintptr_t start = info->dlpi_addr + ph.p_vaddr;
    holds = holds || (ph.p_type == PT_LOAD && search->address >= start && search->address < start + ph.p_memsz);
  }
  if (!holds) return 0;
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[i];
    if (ph.p_type != PT_NOTE) continue;
    const char* at = reinterpret_cast<const char*>(info->dlpi_addr + ph.p_vaddr);
    const char* end = at + ph.p_memsz;
    while (at + sizeof(ElfW(Nhdr)) <= end) {
      ElfW(Nhdr) note;
      std::memcpy(&note, at, sizeof note);
      const char* name = at + sizeof note;
      const char* desc = name + ((note.n_namesz + 3) & ~3u);
      if (note.n_type == NT_GNU_BUILD_ID && note.n_namesz == 4 && std::memcmp(name, "GNU", 4) == 0 &&
          desc + note.n_descsz <= end) {
        static const char hex[] = "0123456789abcdef";
        for (std::size_t k = 0; k < note.n_descsz; ++k) {
          auto byte = static_cast<unsigned char>(desc[k]);
          search->id += hex[byte >> 4];
          search->id += hex[byte & 15];
        }
        return 1;
      }
      at = desc + ((note.n_descsz + 3) & ~3u);
    }
  }
  return 1;
}

}  // namespace

std::string build_id(const void* address) {
  BuildIdSearch search{reinterpret_cast<std::uintptr_t>(address), {}};
  dl_iterate_phdr(find_build_id, &search);
  return search.id;
}

}  // namespace sh::detail
