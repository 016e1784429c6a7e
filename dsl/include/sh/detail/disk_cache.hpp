#pragma once
// What the language keeps on disk between processes (the IR passes'
// results, a backend's machine code): where, under which names, and how a
// file is written so that a reader never sees half of it.  Caching is a
// saving, never a failure: every function here gives up without an error
// (cache_directory says once why it cannot use a directory).
#include <cstdint>
#include <optional>
#include <string>

namespace sh::detail {

// $SH_CACHE_DIR ("off": no cache), else $XDG_CACHE_HOME/sh, else
// ~/.cache/sh; created on first use, for its owner alone (one of ours
// that others could write in is made ours alone).  None where caching is
// off or there is no home, and, said once on stderr, where the directory
// cannot be used: not a directory, not writable, or another user's (whose
// files would run as this process's machine code).  A file in it that
// another user owns reads as none.
std::optional<std::string> cache_directory();

// The file for `key` in the cache directory: <dir>/<kind>-<64-bit FNV-1a of
// the key, hex>.  None where caching is off.
std::optional<std::string> cache_path(const std::string& kind, const std::string& key);

// Writes through a temporary file renamed into place; a failure leaves
// nothing behind, and an entry larger than the process's file-size limit
// is not written.  The file ends in a checksum of the bytes: a file that
// does not match it (damaged on disk, cut short) reads as none, and is
// computed afresh, never loaded (a damaged object file would run).
void write_cache_file(const std::string& path, const std::string& bytes);
std::optional<std::string> read_cache_file(const std::string& path);

// The cache's size: $SH_CACHE_LIMIT_MB mebibytes, 1024 by default.  Past it
// the least recently used entries are removed, down to three quarters of
// it, when a store finds the directory due a scan (a process's first store
// an hour after the last scan, then after each quarter of the limit it
// stores); a scan also removes temporaries ten minutes old, left by a
// writer that was killed.  Only files named as entries are touched.
std::uintmax_t cache_limit_bytes();
void prune_cache(const std::string& dir, std::uintmax_t limit);

// The GNU build ID of the loaded program or library holding `address`, in
// hex: which build of our code made what a cache holds.  Empty where the
// object has none.
std::string build_id(const void* address);

}  // namespace sh::detail
