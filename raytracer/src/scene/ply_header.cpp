#include "ply_header.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "sh/error.hpp"

namespace sh::rt {
namespace {

// Longer than any header line a writer makes (a comment included).
constexpr std::size_t kLongestHeaderLine = 64 * 1024;

struct Element {
  std::string name, count_text;
  std::uint64_t count = 0;
  std::size_t line = 0;
  // The fewest bytes an instance takes: in binary its scalars' and its
  // lists' counts' sizes, in text a character a value.
  std::uint64_t least_bytes = 0;
  // The library skips a binary property of a type it does not know, and
  // the element's properties after it: they bound nothing.
  bool skips_the_rest = false;
};

struct Header {
  std::vector<Element> elements;
  bool binary = false;
  std::uint64_t data_bytes = UINT64_MAX;  // after the end_header line; unknown bounds nothing
};

std::uint64_t binary_size(const std::string& type) {
  for (const char* t : {"char", "uchar", "int8", "uint8"})
    if (type == t) return 1;
  for (const char* t : {"short", "ushort", "int16", "uint16"})
    if (type == t) return 2;
  for (const char* t : {"int", "uint", "float", "int32", "uint32", "float32"})
    if (type == t) return 4;
  for (const char* t : {"double", "float64"})
    if (type == t) return 8;
  return 0;
}

// Whether the file begins as the library's PLY reader takes it: "ply" in
// any case, then the end of that word.  Only a few bytes are read, so a
// file of another format with a long first line is left alone.
bool begins_as_ply(std::istream& in) {
  char start[4] = {};
  in.read(start, sizeof start);
  std::streamsize got = in.gcount();
  if (got < 3) return false;
  for (int i = 0; i < 3; ++i)
    if (std::tolower(static_cast<unsigned char>(start[i])) != "ply"[i]) return false;
  return got == 3 || std::isspace(static_cast<unsigned char>(start[3]));
}

// The header's lines as the library reads them: ended by "\n", "\r",
// "\0" or "\f" ("\r\n" is one end), numbered as an editor shows them (a
// "\0" or "\f" starts no new line there).
class HeaderLines {
 public:
  HeaderLines(std::istream& in, const std::string& path) : in_(in), path_(path) {}
  // The next line without its end; false at the end of the file.
  bool next(std::string& line);
  std::size_t number() const { return number_; }  // of the line next() gave last

 private:
  std::istream& in_;
  const std::string& path_;
  std::size_t number_ = 0, next_number_ = 1;
};

bool HeaderLines::next(std::string& line) {
  line.clear();
  std::size_t starts = next_number_;
  char c;
  bool ended = false;
  while (!ended && in_.get(c)) {
    ended = c == '\n' || c == '\r' || c == '\0' || c == '\f';
    if (c == '\r' && in_.peek() == '\n') in_.get(c);
    if (c == '\n' || c == '\r') ++next_number_;
    if (ended) break;
    if (line.size() > kLongestHeaderLine)
      throw Error(path_ + ": line " + std::to_string(starts) + " of the PLY header is longer than " +
                  std::to_string(kLongestHeaderLine) + " bytes");
    line += c;
  }
  if (!ended && line.empty()) return false;
  number_ = starts;
  return true;
}

std::string plural(std::uint64_t n, const char* unit) {
  return std::to_string(n) + " " + unit + (n == 1 ? "" : "s");
}

// A line's words as the library splits them: at spaces and tabs only (a
// vertical tab is part of a word, so "end_header\v" ends no header).
std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  for (std::size_t at = line.find_first_not_of(" \t"); at != std::string::npos; at = line.find_first_not_of(" \t", at)) {
    std::size_t end = line.find_first_of(" \t", at);
    out.push_back(line.substr(at, end - at));
    at = end;
  }
  return out;
}

// An element line's count; a count that is not a number bounds nothing
// (0), and one past 64 bits everything.
std::uint64_t count_of(const std::string& text) {
  std::uint64_t count = 0;
  auto [end, status] = std::from_chars(text.data(), text.data() + text.size(), count);
  if (end != text.data() + text.size()) return 0;
  return status == std::errc::result_out_of_range ? UINT64_MAX : count;
}

void add_property(Element& e, const std::vector<std::string>& words, bool binary) {
  if (!binary) {
    e.least_bytes += 1;
    return;
  }
  std::uint64_t size = binary_size(words[words[1] == "list" && words.size() > 2 ? 2 : 1]);
  if (size == 0) e.skips_the_rest = true;
  if (!e.skips_the_rest) e.least_bytes += size;
}

// The rest of the header, after the first line; throws where it has no end.
Header read_header(std::istream& in, const std::string& path) {
  Header h;
  HeaderLines lines(in, path);
  std::string line;
  lines.next(line);
  for (;;) {
    if (!lines.next(line))
      throw Error(path + ": the PLY header has no end_header line (the file ends at line " + std::to_string(lines.number()) + ")");
    std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format" && w.size() > 1) h.binary = w[1] != "ascii";
    if (w[0] == "element" && w.size() >= 3) h.elements.push_back({w[1], w[2], count_of(w[2]), lines.number()});
    if (w[0] == "property" && !h.elements.empty() && w.size() > 1) add_property(h.elements.back(), w, h.binary);
  }
  in.clear();  // an end_header line without a line end leaves the stream failed
  auto header_bytes = in.tellg();
  std::error_code error;
  auto size = std::filesystem::file_size(path, error);
  if (!error && header_bytes >= 0) h.data_bytes = size - static_cast<std::uint64_t>(header_bytes);
  return h;
}

// Instances follow one another, so the elements' least bytes add up.  A
// text instance is a line of its own, a byte at least even without
// properties; a binary instance of no property takes none, but the library
// walks every one, so a byte each is the tracer's bound there.
void check_counts(const Header& h, const std::string& path) {
  std::uint64_t before = 0;
  for (const Element& e : h.elements) {
    std::uint64_t least = std::max<std::uint64_t>(e.least_bytes, 1);
    if (e.count > (h.data_bytes - before) / least) {
      std::string each = e.least_bytes > 0 ? "instances of " + plural(least, "byte") + " at least"
                                           : std::string("instances of no property (") +
                                                 (h.binary ? "the tracer's bound: a byte each)" : "a line each)");
      throw Error(path + ": line " + std::to_string(e.line) + ": element '" + e.name + "' has " + e.count_text + " " +
                  each + ", more than the " + plural(h.data_bytes - before, "byte") + " the file has after the PLY header" +
                  (before > 0 ? " and the elements before it" : ""));
    }
    before += e.count * (h.binary ? e.least_bytes : least);
  }
}

}  // namespace

void check_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!begins_as_ply(in)) return;
  in.clear();
  in.seekg(0);
  check_counts(read_header(in, path), path);
}

}  // namespace sh::rt
