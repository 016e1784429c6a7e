#include "sh/detail/disk_cache.hpp"

#include <elf.h>
#include <link.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "../fnv1a.hpp"

namespace sh::detail {
namespace {

namespace fs = std::filesystem;

// When the directory was last scanned for pruning: its time.
constexpr const char* kScanStamp = ".sh-cache-scanned";

// The checksum that ends every cache file: 8 bytes, this host's order.
constexpr std::size_t kChecksumBytes = sizeof(std::uint64_t);

// Each message once a process: a cache quietly off, or a limit quietly
// not the one asked for, would leave its user with nothing to say why.
void say_once(const std::string& message) {
  static std::mutex said_mutex;
  static std::set<std::string> said;
  std::lock_guard lock(said_mutex);
  if (said.insert(message).second) std::fprintf(stderr, "sh: %s\n", message.c_str());
}

void say_not_used(const std::string& dir, const std::string& why) {
  say_once("the kernel cache '" + dir + "' is not used: " + why);
}

// Why the directory cannot hold this user's machine code, or "".  Another
// user who can write in it could plant an object file that would run as
// ours.
std::string unusable(const std::string& dir) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) return std::string("it cannot be created (") + std::strerror(errno) + ")";
  if (!S_ISDIR(st.st_mode)) return "it is not a directory";
  if (st.st_uid != ::geteuid()) return "it belongs to another user, whose files would run as this process's code";
  // Ours, but others may write in it (made under umask 002): ours alone
  // from now on; a file someone else put there is never read.
  if ((st.st_mode & (S_IWGRP | S_IWOTH)) && ::chmod(dir.c_str(), st.st_mode & 07755 & ~(S_IWGRP | S_IWOTH)) != 0)
    return "others can write in it, and their files would run as this process's code (chmod go-w it)";
  if (::access(dir.c_str(), W_OK | X_OK) != 0) return "it is not writable";
  return "";
}

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
  if (fs::create_directories(dir, ignored)) ::chmod(dir.c_str(), 0700);
  if (std::string why = unusable(dir); !why.empty()) {
    say_not_used(dir, why);
    return std::nullopt;
  }
  return dir;
}

std::optional<std::string> cache_path(const std::string& kind, const std::string& key) {
  std::optional<std::string> dir = cache_directory();
  if (!dir) return std::nullopt;
  std::ostringstream name;
  name << *dir << "/" << kind << "-" << std::hex << fnv1a(key);
  return name.str();
}

namespace {

// Entries are named <kind>-<hex>[.o|.bc] and their temporaries the same
// with .tmp<pid>.<n>: nothing else in the directory is ours to remove
// ($SH_CACHE_DIR may name a directory that holds other files).
bool digits(const std::string& s, std::size_t from, std::size_t to) {
  return to > from && std::all_of(s.begin() + from, s.begin() + to, [](char c) { return c >= '0' && c <= '9'; });
}

bool ours(const std::string& name, bool& temporary) {
  std::size_t dash = name.find('-');
  if (dash == 0 || dash == std::string::npos) return false;
  if (!std::all_of(name.begin(), name.begin() + dash, [](char c) { return c >= 'a' && c <= 'z'; })) return false;
  auto lower_hex = [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); };
  std::size_t at = dash + 1;
  while (at < name.size() && lower_hex(name[at])) ++at;
  if (at == dash + 1 || at - dash - 1 > 16) return false;
  for (const char* extension : {".o", ".bc"})
    if (name.compare(at, std::strlen(extension), extension) == 0) {
      at += std::strlen(extension);
      break;
    }
  temporary = name.compare(at, 4, ".tmp") == 0;
  if (!temporary) return at == name.size();
  std::size_t dot = name.find('.', at + 4);
  return dot != std::string::npos && digits(name, at + 4, dot) && digits(name, dot + 1, name.size());
}

struct Entry {
  fs::path path;
  std::uintmax_t bytes;
  fs::file_time_type used;
};

}  // namespace

std::uintmax_t cache_limit_bytes() {
  constexpr std::uintmax_t kDefaultMiB = 1024;
  std::uintmax_t mib = kDefaultMiB;
  if (const char* set = std::getenv("SH_CACHE_LIMIT_MB"); set && *set) {
    char* end = nullptr;
    unsigned long long read = std::strtoull(set, &end, 10);
    if (*end == '\0' && set[0] != '-' && read > 0 && read < (1ull << 40))
      mib = read;
    else
      say_once("SH_CACHE_LIMIT_MB='" + std::string(set) + "' is not a number of MiB from 1 to 2^40 - 1: the kernel " +
               "cache is kept under " + std::to_string(kDefaultMiB) + " MiB");
  }
  return mib << 20;
}

void prune_cache(const std::string& dir, std::uintmax_t limit) {
  const auto stale = fs::file_time_type::clock::now() - std::chrono::minutes(10);
  std::vector<Entry> entries;
  std::uintmax_t total = 0;
  std::error_code walking, ignored;
  for (fs::directory_iterator it(dir, walking), end; !walking && it != end; it.increment(walking)) {
    bool temporary = false;
    if (!ours(it->path().filename().string(), temporary) || !it->is_regular_file(ignored)) continue;
    std::error_code read;
    Entry entry{it->path(), it->file_size(read), it->last_write_time(read)};
    if (read) continue;
    if (temporary) {
      if (entry.used < stale) fs::remove(entry.path, ignored);  // its writer was killed mid-write
      continue;
    }
    total += entry.bytes;
    entries.push_back(std::move(entry));
  }
  if (total <= limit) return;
  // Least recently used first (a hit refreshes an entry's time), down to
  // three quarters of the limit so that the next scan is not at once.
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used; });
  for (const Entry& entry : entries) {
    if (total <= limit / 4 * 3) break;
    if (fs::remove(entry.path, ignored)) total -= entry.bytes;
  }
}

namespace {

// A scan of the directory at a process's first store where the last scan
// (by any process) is an hour old, and again after each quarter of the
// limit this process stores.
void prune_when_due(const std::string& path, std::size_t bytes) {
  static std::mutex due_mutex;
  static std::map<std::string, std::uintmax_t> stored_since_scan;
  std::string dir = fs::path(path).parent_path().string();
  std::uintmax_t limit = cache_limit_bytes();
  fs::path stamp = fs::path(dir) / kScanStamp;
  std::lock_guard lock(due_mutex);
  auto [at, first] = stored_since_scan.try_emplace(dir, 0);
  at->second += bytes;
  std::error_code missing;
  auto hour_ago = fs::file_time_type::clock::now() - std::chrono::hours(1);
  bool due = first ? fs::last_write_time(stamp, missing) < hour_ago || missing : at->second > limit / 4;
  if (!due) return;
  std::ofstream{stamp, std::ios::app};  // made where missing, never cut
  std::error_code ignored;
  fs::last_write_time(stamp, fs::file_time_type::clock::now(), ignored);
  prune_cache(dir, limit);
  at->second = 0;
}

// Under a file-size limit (ulimit -f) a longer write would end the process
// (SIGXFSZ): such an entry is not kept.
bool within_file_size_limit(std::size_t bytes) {
  rlimit limit{};
  return ::getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY || bytes <= limit.rlim_cur;
}

}  // namespace

void write_cache_file(const std::string& path, const std::string& bytes) {
  if (!within_file_size_limit(bytes.size() + kChecksumBytes)) return;
  // A name of this write's own: two threads (or processes) storing one
  // entry never write one file.
  static std::atomic<unsigned> writes{0};
  std::string tmp = path + ".tmp" + std::to_string(::getpid()) + "." + std::to_string(writes++);
  std::error_code ignored;
  std::ofstream out(tmp, std::ios::binary);
  std::uint64_t checksum = fnv1a(bytes);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.write(reinterpret_cast<const char*>(&checksum), kChecksumBytes);
  out.close();
  if (!out) {  // a full disk: nothing left behind
    fs::remove(tmp, ignored);
    return;
  }
  fs::rename(tmp, path, ignored);
  if (ignored) fs::remove(tmp, ignored);
  prune_when_due(path, bytes.size());
}

std::optional<std::string> read_cache_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || st.st_uid != ::geteuid()) return std::nullopt;  // another user's: never run
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream read;
  read << in.rdbuf();
  std::string bytes = read.str();
  if (bytes.size() < kChecksumBytes) return std::nullopt;
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, bytes.data() + bytes.size() - kChecksumBytes, kChecksumBytes);
  bytes.resize(bytes.size() - kChecksumBytes);
  if (fnv1a(bytes) != checksum) return std::nullopt;
  std::error_code ignored;
  fs::last_write_time(path, fs::file_time_type::clock::now(), ignored);  // used: the last to be pruned
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
