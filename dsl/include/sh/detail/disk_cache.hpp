#pragma once
// What the language keeps on disk between processes (the IR passes'
// results, a backend's machine code): where, under which names, and how a
// file is written so that a reader never sees half of it.  Caching is a
// saving, never a failure: every function here gives up quietly.
#include <optional>
#include <string>

namespace sh::detail {

// $SH_CACHE_DIR ("off": no cache), else $XDG_CACHE_HOME/sh, else
// ~/.cache/sh; created on first use.  None where caching is off or there
// is no home.
std::optional<std::string> cache_directory();

// The file for `key` in the cache directory: <dir>/<kind>-<64-bit FNV-1a of
// the key, hex>.  None where caching is off.
std::optional<std::string> cache_path(const std::string& kind, const std::string& key);

// Writes through a temporary file renamed into place; a failure leaves
// nothing behind.  The file ends in a checksum of the bytes: a file that
// does not match it (damaged on disk, cut short) reads as none, and is
// computed afresh, never loaded (a damaged object file would run).
void write_cache_file(const std::string& path, const std::string& bytes);
std::optional<std::string> read_cache_file(const std::string& path);

// The GNU build ID of the loaded program or library holding `address`, in
// hex: which build of our code made what a cache holds.  Empty where the
// object has none.
std::string build_id(const void* address);

}  // namespace sh::detail
