#include "ply_library_header.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>

namespace sh::rt {
namespace {

bool spacing(char c) { return c == ' ' || c == '\t'; }

// The library's line buffer: what it holds from its front on, zeros after
// it.  The library erases what it reads from the front; here the front
// moves instead, so that passing over a word costs nothing and a place in
// the buffer can be kept and gone back to.
class LineBuffer {
 public:
  char at(std::size_t i) const { return front_ + i < bytes_.size() ? bytes_[front_ + i] : '\0'; }
  void set(std::size_t i, char c) {
    if (front_ + i >= bytes_.size()) bytes_.resize(front_ + i + 1, '\0');
    bytes_[front_ + i] = c;
  }
  void drop(std::size_t n) { front_ = std::min(front_ + n, bytes_.size()); }
  std::size_t front() const { return front_; }
  void go_back_to(std::size_t front) { front_ = front; }
  // What it holds up to the end of its first line.
  std::string line_text() const {
    std::size_t end = bytes_.find_first_of(std::string("\n\r\f\0", 4), front_);
    return bytes_.substr(front_, end == std::string::npos ? std::string::npos : end - front_);
  }

  // The library's ways of moving along a line; each drops what it passes.
  bool skip_spaces() {
    std::size_t n = 0;
    while (spacing(at(n))) ++n;
    drop(n);
    return !ends_ply_line(at(0));
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
    if (!spacing(after) && !ends_ply_line(after)) return false;
    drop(word.size() + (after != '\0' ? 1 : 0));
    return true;
  }
  bool any_token(std::initializer_list<const char*> words) {
    for (const char* w : words)
      if (token(w)) return true;
    return false;
  }

 private:
  std::string bytes_;
  std::size_t front_ = 0;
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
  void skip_comments(LineBuffer& b);
  bool element(LineBuffer& b, LibraryPlyElement& e, bool binary);
  bool property(LineBuffer& b, LibraryPlyElement& e, bool binary);
  bool header(LineBuffer& b, LibraryPlyHeader& h);

  const std::string& file_;
  bool whole_;
  std::size_t pos_ = 0;
  std::size_t newlines_ = 0;  // line feeds before pos_
  std::size_t line_ = 0;      // the file's line next_line read last (as an editor numbers it)
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
  if (ends_ply_line(byte(pos_))) {
    while (byte(pos_) != '\n') ++pos_;
    ++newlines_;
    if (++pos_ >= end) return false;
  }
  line_ = newlines_ + 1;
  std::size_t i = 0;
  while (!ends_ply_line(byte(pos_))) {
    b.set(i++, byte(pos_));
    if (++pos_ >= end) return false;
  }
  b.set(i, '\n');
  if (byte(pos_++) == '\n') ++newlines_;
  return true;
}

// A comment is passed over to the end of its line (into the leftovers
// after it), but for a texture's, which stays to be read as an element.
void LibraryReader::skip_comments(LineBuffer& b) {
  std::size_t front = b.front();
  if (!b.skip_spaces() || !b.token("comment")) return b.go_back_to(front);
  if (!b.skip_spaces()) b.skip_line();
  if (b.token("TextureFile")) return b.go_back_to(front);
  b.skip_line();
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
  e.line = line_;
  bool known = false;
  for (const char* name : {"vertex", "face", "tristrips", "edge", "material", "TextureFile"})
    if (b.token(name)) {
      e.name = name;
      known = true;
      break;
    }
  if (!known) e.name = b.line_text();
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
// its last line again for ever (the file ends first).  Past the file's end
// nothing is written to the buffer, so the library is stuck once a line
// it cannot read finds the buffer's front where the last one did.
bool LibraryReader::header(LineBuffer& b, LibraryPlyHeader& h) {
  std::size_t stalled_at = SIZE_MAX;
  for (;;) {
    skip_comments(b);
    LibraryPlyElement e;
    if (element(b, e, h.binary)) {
      h.elements.push_back(e);
      continue;
    }
    if (b.token("end_header")) return true;
    if (!next_line(b)) {
      if (b.front() == stalled_at) return false;
      stalled_at = b.front();
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
  if (h.binary && format.line_text().compare(0, 7, "binary_") != 0) return h;
  h.read = true;
  next_line(b);
  h.ends = header(b, h);
  h.line = line_;
  if (!h.ends) return h;
  // Binary data from the next byte (a "\n" left of a "\r\n" passed over);
  // text from the next line.
  h.data_start = pos_ + (h.binary && byte(pos_) == '\n' ? 1 : 0);
  return h;
}

}  // namespace

LibraryPlyHeader read_like_the_library(const std::string& start, bool whole) { return LibraryReader(start, whole).read(); }

}  // namespace sh::rt
