#pragma once
// A PLY header as the model library (Debian 12's assimp 5.2.5) reads it,
// its quirks included: it ends a line at "\n", "\r", "\0" or "\f"; where a
// line begins with "\r", "\0" or "\f" it passes over everything up to the
// next "\n"; it reads each line into a buffer that keeps what longer lines
// before it left there, and after a comment reads on into those leftovers;
// at the end of the file it reads its last line again, for ever where that
// line does not end the header.  The header check (ply_header.hpp) asks
// this what the library would do.
#include <cstdint>
#include <string>
#include <vector>

namespace sh::rt {

struct LibraryPlyElement {
  std::string name;
  std::string digits;       // the count as written
  std::uint32_t count = 0;  // and as the library reads it (modulo 2^32)
  // The fewest bytes an instance takes: in binary its scalars' and its
  // lists' counts' sizes, in text a character a value.
  std::uint64_t least_bytes = 0;
  std::size_t line = 0;  // the file's line the library read it from
};

struct LibraryPlyHeader {
  bool read = false;   // the library takes the file (its magic and format lines)
  bool ends = false;   // it finds the header's end; else it never stops reading
  bool binary = false;
  std::size_t line = 0;  // the file's line where the header ends, or the last one read
  std::vector<LibraryPlyElement> elements;
  std::uint64_t data_start = 0;  // the byte the library reads data from
};

// Whether the library ends a PLY line at `c`.
inline bool ends_ply_line(char c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }

// `start` holds the file's first bytes (all of them where `whole`); throws
// std::length_error where the header runs past them.
LibraryPlyHeader read_like_the_library(const std::string& start, bool whole);

}  // namespace sh::rt
