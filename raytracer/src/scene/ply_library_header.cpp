#include "ply_library_header.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>

namespace sh::rt {
namespace {

bool ends_line(char c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }
bool spacing(char c) { return c == ' ' || c == '\t'; }

// The library's line buffer: what it holds now, zeros after it.
class LineBuffer {
 public:
  char at(std::size_t i) const { return i < bytes_.size() ? bytes_[i] : '\0'; }
  void set(std::size_t i, char c) {
    if (i >= bytes_.size()) bytes_.resize(i + 1, '\0');
    bytes_[i] = c;
  }
  void drop(std::size_t n) { bytes_.erase(0, std::min(n, bytes_.size())); }
  bool operator==(const LineBuffer& other) const { return trimmed() == other.trimmed(); }
  // What it holds up to its first zero.
  std::string text() const { return bytes_.substr(0, bytes_.find('\0')); }

  // The library's ways of moving along a line; each drops what it passes.
  bool skip_spaces() {
    std::size_t n = 0;
    while (spacing(at(n))) ++n;
    drop(n);
    return !ends_line(at(0));
  }
  bool skip_line() {
    std::size_t n = 0;
    while (at(n) != '\r' && at(n) != '\n' && at(n) != '\0') ++n;
    while (at(n) == '\r' || at(n) == '\n') ++n;
    drop(n);
    return at(0) != '\0';
  }
  void skip_spaces_and_line_ends() {
    std::size_t n = 0;
    while (spacing(at(n)) || at(n) == '\r' || at(n) == '\n') ++n;
    drop(n);
  }
  // The word, then a space or line end (passed too, but for a zero).
  bool token(const std::string& word) {
    for (std::size_t i = 0; i < word.size(); ++i)
      if (at(i) != word[i]) return false;
    char after = at(word.size());
    if (!spacing(after) && !ends_line(after)) return false;
    drop(word.size() + (after != '\0' ? 1 : 0));
    return true;
  }
  bool any_token(std::initializer_list<const char*> words) {
    for (const char* w : words)
      if (token(w)) return true;
    return false;
  }

 private:
  std::string trimmed() const { return bytes_.substr(0, bytes_.find_last_not_of('\0') + 1); }
  std::string bytes_;
};

// A scalar type's size, 0 where the library knows no such type.
std::uint64_t data_type(LineBuffer& b) {
  if (b.any_token({"char", "int8", "uchar", "uint8"})) return 1;
  if (b.any_token({"short", "int16", "ushort", "uint16"})) return 2;
  if (b.any_token({"int32", "int", "uint32", "uint", "float", "float32"})) return 4;
  if (b.any_token({"double64", "double", "float64"})) return 8;
  return 0;
}

class LibraryReader {
 public:
  LibraryReader(const std::string& start, bool whole) : file_(start), whole_(whole) {}
  LibraryPlyHeader read();

 private:
  char byte(std::size_t at) const;
  bool next_line(LineBuffer& b);
  std::size_t line_at(std::size_t at) const;
  void skip_comments(LineBuffer& b);
  bool element(LineBuffer& b, LibraryPlyElement& e, bool binary);
  bool property(LineBuffer& b, LibraryPlyElement& e, bool binary);
  bool header(LineBuffer& b, LibraryPlyHeader& h);

  const std::string& file_;
  bool whole_;
  std::size_t pos_ = 0;
  std::size_t line_start_ = 0;  // where the line next_line read last began
};

// Past a whole file's end the library's cache holds line feeds.
char LibraryReader::byte(std::size_t at) const {
  if (at < file_.size()) return file_[at];
  if (!whole_) throw std::length_error("the PLY header runs past the bytes read");
  return '\n';
}

bool LibraryReader::next_line(LineBuffer& b) {
  std::size_t end = whole_ ? file_.size() : SIZE_MAX;
  if (pos_ >= end) return false;
  if (ends_line(byte(pos_))) {
    while (byte(pos_) != '\n') ++pos_;
    if (++pos_ >= end) return false;
  }
  line_start_ = pos_;
  std::size_t i = 0;
  while (!ends_line(byte(pos_))) {
    b.set(i++, byte(pos_));
    if (++pos_ >= end) return false;
  }
  b.set(i, '\n');
  ++pos_;
  return true;
}

std::size_t LibraryReader::line_at(std::size_t at) const {
  return 1 + static_cast<std::size_t>(std::count(file_.begin(), file_.begin() + static_cast<std::ptrdiff_t>(std::min(at, file_.size())), '\n'));
}

// A comment is passed over to the end of its line (into the leftovers
// after it), but for a texture's, which stays to be read as an element.
void LibraryReader::skip_comments(LineBuffer& b) {
  LineBuffer rest = b;
  if (!rest.skip_spaces() || !rest.token("comment")) return;
  if (!rest.skip_spaces()) rest.skip_line();
  if (rest.token("TextureFile")) return;
  rest.skip_line();
  b = rest;
}

bool LibraryReader::property(LineBuffer& b, LibraryPlyElement& e, bool binary) {
  if (!b.skip_spaces() || !b.token("property") || !b.skip_spaces()) return false;
  std::uint64_t size = 0;
  if (b.token("list")) {
    size = data_type(b);
    if (size == 0) return b.skip_line(), false;
    if (!b.skip_spaces()) return false;
  }
  std::uint64_t scalar = data_type(b);
  if (scalar == 0) return b.skip_line(), false;
  if (size == 0) size = scalar;
  if (!b.skip_spaces()) return false;
  // A name the library does not know it passes over to the next line.
  bool known = b.any_token({"red", "green", "blue", "alpha", "vertex_index", "vertex_indices", "texcoord", "material_index",
               "ambient_red", "ambient_green", "ambient_blue", "ambient_alpha", "diffuse_red", "diffuse_green",
               "diffuse_blue", "diffuse_alpha", "specular_red", "specular_green", "specular_blue", "specular_alpha",
               "opacity", "specular_power", "r", "g", "b", "u", "s", "tx", "texture_u", "v", "t", "ty", "texture_v",
               "x", "y", "z", "nx", "ny", "nz"});
  if (!known) b.skip_line();
  b.skip_spaces_and_line_ends();
  e.least_bytes += binary ? size : 1;
  return true;
}

// "element NAME COUNT" (or "comment ...": the library takes either), then
// its properties, line by line until one is not.
bool LibraryReader::element(LineBuffer& b, LibraryPlyElement& e, bool binary) {
  if (!b.skip_spaces() || !b.any_token({"element", "comment"}) || !b.skip_spaces()) return false;
  e.line = line_at(line_start_);
  bool known = false;
  for (const char* name : {"vertex", "face", "tristrips", "edge", "material", "TextureFile"})
    if (b.token(name)) {
      e.name = name;
      known = true;
      break;
    }
  if (!known) e.name = b.text().substr(0, b.text().find_first_of("\n\r\f"));
  if (!b.skip_spaces()) return false;
  if (e.name == "TextureFile") {
    b.skip_spaces_and_line_ends();
    return true;
  }
  for (std::size_t i = 0; b.at(i) >= '0' && b.at(i) <= '9'; ++i) {
    e.digits += b.at(i);
    e.count = e.count * 10u + static_cast<std::uint32_t>(b.at(i) - '0');
  }
  b.skip_spaces_and_line_ends();
  do {
    next_line(b);
    skip_comments(b);
  } while (property(b, e, binary));
  return true;
}

// The header's lines up to end_header; false where the library would read
// its last line again for ever (the file ends first).
bool LibraryReader::header(LineBuffer& b, LibraryPlyHeader& h) {
  LineBuffer stalled;
  bool was_stalled = false;
  for (;;) {
    skip_comments(b);
    LibraryPlyElement e;
    if (element(b, e, h.binary)) {
      h.elements.push_back(e);
      continue;
    }
    if (b.token("end_header")) return true;
    if (!next_line(b)) {
      if (was_stalled && b == stalled) return false;
      stalled = b;
      was_stalled = true;
    }
  }
}

LibraryPlyHeader LibraryReader::read() {
  LibraryPlyHeader h;
  LineBuffer magic, format, b;
  next_line(magic);
  for (int i = 0; i < 3; ++i)
    if (std::tolower(static_cast<unsigned char>(magic.at(i))) != "ply"[i]) return h;
  next_line(format);
  format.skip_spaces_and_line_ends();
  if (!format.token("format")) return h;
  h.binary = !format.token("ascii");
  if (h.binary && format.text().compare(0, 7, "binary_") != 0) return h;
  h.read = true;
  next_line(b);
  h.ends = header(b, h);
  h.line = line_at(line_start_);
  if (!h.ends) return h;
  // Binary data from the next byte (a "\n" left of a "\r\n" passed over);
  // text from the next line.
  h.data_start = pos_ + (h.binary && byte(pos_) == '\n' ? 1 : 0);
  return h;
}

}  // namespace

LibraryPlyHeader read_like_the_library(const std::string& start, bool whole) { return LibraryReader(start, whole).read(); }

}  // namespace sh::rt
