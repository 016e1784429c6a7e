#include "ply_header.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "ply_library_header.hpp"
#include "sh/error.hpp"

namespace sh::rt {
namespace {

// More than any header a writer makes; the check reads no further.
constexpr std::size_t kHeaderBytes = 4 << 20;
constexpr std::size_t kFirstBytes = 4 << 10;

std::string printable(const std::string& text) {
  std::string out;
  for (unsigned char c : text.substr(0, 40)) {
    if (c >= 0x20 && c != 0x7f) {
      out += static_cast<char>(c);
      continue;
    }
    char escaped[8];
    std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
    out += escaped;
  }
  return out;
}

std::string plural(std::uint64_t n, const char* unit) {
  return std::to_string(n) + " " + unit + (n == 1 ? "" : "s");
}

// Line ends from byte `from` to the end of the file (any the library
// takes: "\n", "\r", "\0", "\f"), and a line more where the last one has
// none.
std::uint64_t lines_from(const std::string& path, std::uint64_t from) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(from));
  std::uint64_t lines = 0;
  char last = '\n';
  std::vector<char> chunk(1 << 16);
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    auto got = static_cast<std::size_t>(in.gcount());
    lines += static_cast<std::uint64_t>(std::count_if(chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(got), ends_ply_line));
    last = chunk[got - 1];
  }
  return lines + (ends_ply_line(last) ? 0 : 1);
}

class CountCheck {
 public:
  CountCheck(const std::string& path, const LibraryPlyHeader& h, std::uint64_t data_bytes)
      : path_(path), h_(h), data_bytes_(data_bytes) {}
  void run();

 private:
  [[noreturn]] void fail(const LibraryPlyElement& e, const std::string& each, std::uint64_t room, const char* unit,
                         bool after_others) const {
    std::string count = e.digits + (e.digits == std::to_string(e.count) ? "" : " (" + std::to_string(e.count) + " as the model library reads it)");
    throw Error(path_ + ": line " + std::to_string(e.line) + ": element '" + printable(e.name) + "' has " + count + " " +
                each + ", more than the " + plural(room, unit) +
                " the file has after the PLY header" + (after_others ? " and the elements before it" : ""));
  }
  const std::string& path_;
  const LibraryPlyHeader& h_;
  std::uint64_t data_bytes_;
};

// Instances follow one another, so the elements' least bytes add up; in
// text each instance is a line of its own (the library reads the last line
// again for every instance the file lacks).  A binary instance of no
// property takes no bytes, but the library walks every one, so a byte each
// is the tracer's bound there.
void CountCheck::run() {
  std::uint64_t lines = h_.binary ? 0 : lines_from(path_, h_.data_start);
  std::uint64_t bytes_before = 0, lines_before = 0;
  for (const LibraryPlyElement& e : h_.elements) {
    std::uint64_t least = std::max<std::uint64_t>(e.least_bytes, 1);
    if (e.count > (data_bytes_ - bytes_before) / least) {
      std::string each = e.least_bytes > 0 ? "instances of " + plural(least, "byte") + " at least"
                                           : std::string("instances of no property (") +
                                                 (h_.binary ? "the tracer's bound: a byte each)" : "a line each)");
      fail(e, each, data_bytes_ - bytes_before, "byte", bytes_before > 0);
    }
    if (!h_.binary && e.count > lines - lines_before)
      fail(e, "instances of a line each", lines - lines_before, "line", lines_before > 0);
    bytes_before += e.count * (h_.binary ? e.least_bytes : least);
    lines_before += e.count;
  }
}

// The header as the library reads it, from the file's first bytes: a few
// at first (headers are short, and the load may run under a tight memory
// limit), more while the header runs past them.
LibraryPlyHeader read_header(const std::string& path, std::uint64_t size) {
  std::ifstream in(path, std::ios::binary);
  std::string start;
  for (std::size_t want = kFirstBytes;; want *= 4) {
    std::size_t had = start.size();
    start.resize(want);
    in.read(start.data() + had, static_cast<std::streamsize>(want - had));
    start.resize(had + static_cast<std::size_t>(in.gcount()));
    try {
      return read_like_the_library(start, size <= start.size());
    } catch (const std::length_error&) {
      if (want >= kHeaderBytes)
        throw Error(path + ": the PLY header runs past its first " + std::to_string(kHeaderBytes >> 20) + " MiB");
    }
  }
}

}  // namespace

void check_ply_header(const std::string& path) {
  std::error_code error;
  std::uint64_t size = std::filesystem::file_size(path, error);
  if (error) return;  // the loader names what is wrong with the file
  LibraryPlyHeader h = read_header(path, size);
  if (!h.read) return;  // the library refuses the file at once
  if (!h.ends)
    throw Error(path + ": the model library finds no end_header line it can read in this PLY header: it reads on to "
                "line " + std::to_string(h.line) + " and then reads it again for ever (a header line ends with \\n or "
                "\\r\\n, its words are parted by spaces and tabs)");
  CountCheck(path, h, size > h.data_start ? size - h.data_start : 0).run();
}

}  // namespace sh::rt
