#include "ply_header.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "sh/error.hpp"

// The model library's PLY reader ends a header line at "\n", "\r", "\0" or
// "\f" and splits it into words at spaces and tabs; where a line begins
// with "\r", "\0" or "\f" it passes over the line after it, and it reads
// each line into a buffer that keeps what longer lines before it left
// there (after a comment it reads on into those leftovers).  A header it
// cannot end keeps it reading the last line again forever.  The check
// reads the lines as the library does, asks for the format's plain
// grammar in them (where the leftovers hold no word that begins a header
// line), and names the line where a header leaves it.
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
};

struct Header {
  std::vector<Element> elements;
  bool binary = false;
  std::uint64_t data_bytes = UINT64_MAX;  // after the end_header line; unknown bounds nothing
};

// The size of a binary scalar of the type, 0 for a word that names none.
std::uint64_t binary_size(const std::string& type) {
  for (const char* t : {"char", "uchar", "int8", "uint8"})
    if (type == t) return 1;
  for (const char* t : {"short", "ushort", "int16", "uint16"})
    if (type == t) return 2;
  for (const char* t : {"int", "uint", "float", "int32", "uint32", "float32"})
    if (type == t) return 4;
  for (const char* t : {"double", "float64", "double64"})
    if (type == t) return 8;
  return 0;
}

bool ends_line(int c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }

// Whether the library's PLY reader takes the file: its first line (after
// line ends the file may begin with) begins with "ply" in any case.  Only
// the file's start is read, so a file of another format with a long first
// line is left alone.
bool begins_as_ply(std::istream& in) {
  if (ends_line(in.peek())) in.ignore(kLongestHeaderLine, '\n');
  char start[3] = {};
  in.read(start, sizeof start);
  if (in.gcount() < 3) return false;
  for (int i = 0; i < 3; ++i)
    if (std::tolower(static_cast<unsigned char>(start[i])) != "ply"[i]) return false;
  return true;
}

std::string printable(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
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

// The header's lines as the library reads them: a line ends at "\n",
// "\r", "\0" or "\f"; a "\n" where a line would begin is passed over (a
// blank line, or the rest of a "\r\n"), but at a "\r", "\0" or "\f" there
// the library passes over everything up to the next "\n", the next line
// with it, which is an error here.  Lines are numbered as an editor shows
// them ("\n", "\r\n" and a lone "\r" end them).
class HeaderLines {
 public:
  HeaderLines(std::istream& in, const std::string& path) : in_(in), path_(path) {}
  // The next line without its end; false at the end of the file.  `ended`
  // is false for a last line without a line end.
  bool next(std::string& line, bool& ended);
  std::size_t number() const { return number_; }  // of the line next() gave last

 private:
  std::istream& in_;
  const std::string& path_;
  std::size_t number_ = 0, breaks_ = 0;
};

bool HeaderLines::next(std::string& line, bool& ended) {
  line.clear();
  ended = false;
  int first = in_.peek();
  if (first == std::char_traits<char>::eof()) return false;
  number_ = breaks_ + 1;
  if (first != '\n' && ends_line(first))
    throw Error(path_ + ": line " + std::to_string(number_) + " of the PLY header begins with the byte " +
                printable(std::string(1, static_cast<char>(first))) +
                ", where the model library passes over everything up to the next line feed");
  if (first == '\n') {
    in_.get();
    number_ = ++breaks_ + 1;
  }
  char c;
  while (in_.get(c)) {
    if (ends_line(c)) {
      if (c == '\n' || (c == '\r' && in_.peek() != '\n')) ++breaks_;
      return ended = true;
    }
    if (line.size() > kLongestHeaderLine)
      throw Error(path_ + ": line " + std::to_string(number_) + " of the PLY header is longer than " +
                  std::to_string(kLongestHeaderLine) + " bytes");
    line += c;
  }
  return !line.empty();
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

class HeaderReader {
 public:
  HeaderReader(std::istream& in, const std::string& path) : in_(in), path_(path), lines_(in, path) {}
  Header read();

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(path_ + ": line " + std::to_string(lines_.number()) + " of the PLY header: " + why);
  }
  void first_line(const std::string& line);
  void element(const std::vector<std::string>& w);
  void property(const std::vector<std::string>& w);
  void no_keywords(const std::vector<std::string>& w, std::size_t from);
  void ignored(const std::string& line);

  std::istream& in_;
  const std::string& path_;
  HeaderLines lines_;
  Header h_;
  bool begun_ = false;  // a line after the first, blank ones aside, was read
  // The library ends an element's properties at one of a type it does not
  // know: the ones after it bound nothing.
  bool properties_ended_ = false;
};

void HeaderReader::first_line(const std::string& line) {
  std::vector<std::string> w = words(line);
  std::string magic = w.size() == 1 ? w[0] : "";
  std::transform(magic.begin(), magic.end(), magic.begin(), [](unsigned char c) { return std::tolower(c); });
  if (magic != "ply") fail("the first line is '" + printable(line) + "', not 'ply'");
}

// The words that begin header lines.  The library keeps what a line leaves
// in its buffer and may read it again after a shorter comment line, from
// any byte on, so a line it ignores may not hold the words that start an
// element, a property, a comment or the header's end anywhere, and a name
// may not be a header line's first word.
const char* const kKeywords[] = {"ply", "format", "comment", "obj_info", "element", "property", "end_header"};
const char* const kStarts[] = {"element", "property", "comment", "end_header"};

void HeaderReader::no_keywords(const std::vector<std::string>& w, std::size_t from) {
  for (std::size_t i = from; i < w.size(); ++i)
    for (const char* keyword : kKeywords)
      if (w[i] == keyword) fail("'" + w[i] + "' as a name, where the model library may read it as a header line's first word");
}

// A line the library reads past: obj_info, another format, or any other.
void HeaderReader::ignored(const std::string& line) {
  for (const char* start : kStarts)
    if (line.find(start) != std::string::npos)
      fail("a line the model library passes over ('" + printable(line.substr(0, 40)) + "') holds '" + start +
           "', which the library may read again as a header line");
}

// "element NAME COUNT", the count a decimal number.
void HeaderReader::element(const std::vector<std::string>& w) {
  if (w.size() != 3) fail("an element line is 'element NAME COUNT', not " + plural(w.size(), "word"));
  no_keywords(w, 1);
  properties_ended_ = false;
  Element e{w[1], w[2], 0, lines_.number(), 0};
  auto [end, status] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
  if (w[2].empty() || end != w[2].data() + w[2].size() || !std::isdigit(static_cast<unsigned char>(w[2][0])))
    fail("element '" + printable(w[1]) + "' has the count '" + printable(w[2]) + "', not a number");
  if (status == std::errc::result_out_of_range) e.count = UINT64_MAX;
  h_.elements.push_back(e);
}

// "property TYPE NAME" or "property list COUNT_TYPE TYPE NAME", inside an
// element.
void HeaderReader::property(const std::vector<std::string>& w) {
  if (h_.elements.empty()) fail("a property before any element");
  bool list = w.size() > 1 && w[1] == "list";
  if (w.size() != (list ? 5u : 3u))
    fail(list ? "a list property is 'property list COUNT_TYPE TYPE NAME'" : "a property is 'property TYPE NAME'");
  no_keywords(w, w.size() - 1);
  std::uint64_t size = binary_size(w[list ? 2 : 1]);
  properties_ended_ = properties_ended_ || size == 0 || (list && binary_size(w[3]) == 0);
  if (!properties_ended_) h_.elements.back().least_bytes += h_.binary ? size : 1;
}

Header HeaderReader::read() {
  std::string line;
  bool ended = false;
  lines_.next(line, ended);
  first_line(line);
  for (;;) {
    if (!lines_.next(line, ended))
      throw Error(path_ + ": the PLY header has no end_header line (the file ends at line " +
                  std::to_string(lines_.number()) + ")");
    std::vector<std::string> w = words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      if (!ended) fail("end_header is the file's last bytes, without a line end, which the model library does not read");
      break;
    }
    bool first = !begun_;
    begun_ = true;
    if (w[0] == "format" && first) {
      h_.binary = w.size() > 1 && w[1] != "ascii";
    } else if (w[0] == "element") {
      element(w);
    } else if (w[0] == "property") {
      property(w);
    } else if (w[0] != "comment") {
      ignored(line);
    }
  }
  auto header_bytes = in_.tellg();
  std::error_code error;
  auto size = std::filesystem::file_size(path_, error);
  if (!error && header_bytes >= 0) h_.data_bytes = size - static_cast<std::uint64_t>(header_bytes);
  return h_;
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
  check_counts(HeaderReader(in, path).read(), path);
}

}  // namespace sh::rt
