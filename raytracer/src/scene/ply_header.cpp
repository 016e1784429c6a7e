#include "ply_header.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "sh/error.hpp"

namespace sh::rt {
namespace {

// Longer than any header line a writer makes (a comment included); a file
// whose "line" runs on past it is binary data, not a header.
constexpr std::size_t kLongestHeaderLine = 64 * 1024;

struct Element {
  std::string name, count_text;
  std::uint64_t count = 0;
  std::size_t line = 0;
  // The fewest bytes an instance takes: in binary its scalars' and its
  // lists' counts' sizes, in text a character a value.  An instance of no
  // property takes none, but the library still reads each one: one byte
  // each bounds those too.
  std::uint64_t least_bytes = 0;
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
  return 1;  // a type the library rejects anyway: the least claim on the data
}

// One line without its end ("\n" or "\r\n"); false at the end of the file
// with nothing read.
bool read_line(std::istream& in, std::string& line, const std::string& path, std::size_t number) {
  line.clear();
  char c;
  while (in.get(c)) {
    if (c == '\n') break;
    if (line.size() == kLongestHeaderLine)
      throw Error(path + ": line " + std::to_string(number) + " of the PLY header is longer than " +
                  std::to_string(kLongestHeaderLine) + " bytes: the header has no end_header line before binary data");
    line += c;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return in || !line.empty();
}

std::string plural(std::uint64_t n, const char* unit) {
  return std::to_string(n) + " " + unit + (n == 1 ? "" : "s");
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

}  // namespace

void check_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!read_line(in, line, path, 1) || line != "ply") return;
  std::vector<Element> elements;
  bool binary = false;
  std::size_t number = 1;
  for (;;) {
    if (!read_line(in, line, path, ++number))
      throw Error(path + ": the PLY header has no end_header line (the file ends at line " + std::to_string(number - 1) + ")");
    std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format" && w.size() > 1) binary = w[1] != "ascii";
    if (w[0] == "property" && !elements.empty() && w.size() > 1) {
      bool list = w[1] == "list" && w.size() > 2;
      elements.back().least_bytes += binary ? binary_size(w[list ? 2 : 1]) : 1;
    }
    if (w[0] != "element" || w.size() < 3) continue;
    Element e{w[1], w[2], 0, number};
    auto [end, status] = std::from_chars(e.count_text.data(), e.count_text.data() + e.count_text.size(), e.count);
    if (end != e.count_text.data() + e.count_text.size()) continue;  // not a count: the library rejects it
    if (status == std::errc::result_out_of_range) e.count = UINT64_MAX;
    elements.push_back(e);
  }
  std::error_code error;
  auto size = std::filesystem::file_size(path, error);
  auto header = in.tellg();
  if (error || header < 0) return;
  std::uint64_t data = size - static_cast<std::uint64_t>(header);
  // Instances follow one another, so the elements' least bytes add up
  // (an instance of no property to none: it reads nothing).
  std::uint64_t before = 0;
  for (const Element& e : elements) {
    std::uint64_t least = std::max<std::uint64_t>(e.least_bytes, 1);
    if (e.count > (data - before) / least)
      throw Error(path + ": line " + std::to_string(e.line) + ": element '" + e.name + "' has " + e.count_text +
                  " instances of " + plural(least, "byte") + " at least, more than the " + plural(data - before, "byte") +
                  " the file has after the PLY header" + (before > 0 ? " and the elements before it" : ""));
    before += e.count * e.least_bytes;
  }
}

}  // namespace sh::rt
