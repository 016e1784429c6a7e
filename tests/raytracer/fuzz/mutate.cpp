#include "mutate.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>
#include <vector>

namespace sh::fuzz {
namespace {

using Rng = std::mt19937_64;

std::size_t below(Rng& rng, std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); }

template <typename T, std::size_t N>
const T& pick(Rng& rng, const T (&items)[N]) {
  return items[below(rng, N)];
}

const char* const kSpecialNumbers[] = {"0",          "-1",          "4294967295", "4294967296", "2147483647", "2147483648",
                                       "-2147483648", "99999999999999999999", "1e308", "1e999", "-1e999", "nan",
                                       "inf",        "-inf",        "1e30",       "1e-45",      "65535",      "256"};
const char* const kPoisonCoordinates[] = {"nan", "inf", "-inf", "1e30", "-1e30", "1e39", "-1e39"};

// [begin, end) of each number token ("-1.5e3", "7") in the text.
std::vector<std::pair<std::size_t, std::size_t>> numbers(const std::string& s) {
  std::vector<std::pair<std::size_t, std::size_t>> found;
  for (std::size_t i = 0; i < s.size();) {
    bool starts = std::isdigit(static_cast<unsigned char>(s[i])) ||
                  ((s[i] == '-' || s[i] == '.') && i + 1 < s.size() && std::isdigit(static_cast<unsigned char>(s[i + 1])));
    if (!starts) {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || std::strchr(".eE+-", s[j]))) ++j;
    found.emplace_back(i, j);
    i = j;
  }
  return found;
}

// Line `line`'s [begin, end) in the text.
std::pair<std::size_t, std::size_t> line_span(const std::string& s, std::size_t line) {
  std::size_t begin = 0;
  for (std::size_t l = 0; l < line && begin != std::string::npos; ++l) {
    begin = s.find('\n', begin);
    if (begin != std::string::npos) ++begin;
  }
  if (begin == std::string::npos) return {s.size(), s.size()};
  std::size_t end = s.find('\n', begin);
  return {begin, end == std::string::npos ? s.size() : end};
}

// The k-th whitespace-separated token of a line, after `prefix` if given.
std::pair<std::size_t, std::size_t> token(const std::string& s, std::pair<std::size_t, std::size_t> line, const std::string& prefix,
                                          std::size_t k) {
  std::size_t at = line.first;
  if (!prefix.empty() && s.find(prefix, line.first) < line.second) at = s.find(prefix, line.first) + prefix.size();
  for (std::size_t t = 0;; ++t) {
    while (at < line.second && std::isspace(static_cast<unsigned char>(s[at]))) ++at;
    std::size_t end = at;
    while (end < line.second && !std::isspace(static_cast<unsigned char>(s[end]))) ++end;
    if (t == k) return {at, end};
    at = end;
  }
}

void replace(std::string& s, std::pair<std::size_t, std::size_t> span, const std::string& with) {
  s.replace(span.first, span.second - span.first, with);
}

template <typename T>
void store(std::string& s, std::size_t at, T value) {
  if (at + sizeof(T) <= s.size()) std::memcpy(s.data() + at, &value, sizeof(T));
}

// Targeted: each leaves the file certainly invalid.
std::string poison_vertex(const Seed& seed, std::string& s, Rng& rng) {
  if (!seed.float_offsets.empty()) {
    const float poison[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(), 1e30f, -1e30f};
    std::size_t at = seed.float_offsets[below(rng, seed.float_offsets.size())];
    float value = pick(rng, poison);
    store(s, at, value);
    return "float at byte " + std::to_string(at) + " := " + std::to_string(value);
  }
  std::size_t line = seed.vertex_lines[below(rng, seed.vertex_lines.size())];
  std::string value = pick(rng, kPoisonCoordinates);
  replace(s, token(s, line_span(s, line), seed.vertex_prefix, below(rng, 3)), value);
  return "vertex on line " + std::to_string(line + 1) + " := " + value;
}

std::string bad_index(const Seed& seed, std::string& s, Rng& rng) {
  std::size_t line = seed.face_lines[below(rng, seed.face_lines.size())];
  const char* const past[] = {"99", "2147483647", "4294967295"};
  const char* const obj_past[] = {"99", "-99", "2147483647"};  // OBJ counts from 1, and back from -1
  std::string value = seed.format == "obj" ? pick(rng, obj_past) : pick(rng, past);
  // OBJ: "f a b c" (token 0 after "f "); PLY and OFF: "3 a b c" (the count first).
  std::size_t k = seed.format == "obj" ? below(rng, 3) : 1 + below(rng, 3);
  replace(s, token(s, line_span(s, line), seed.format == "obj" ? "f " : "", k), value);
  return "face on line " + std::to_string(line + 1) + ": index := " + value;
}

std::string deep_nesting(std::string& s, Rng& rng) {
  auto spans = numbers(s);
  std::size_t depth = std::size_t{100} << below(rng, 11);  // 100 .. 102400
  replace(s, spans[below(rng, spans.size())], std::string(depth, '[') + "0" + std::string(depth, ']'));
  return "a number nested in " + std::to_string(depth) + " arrays";
}

// Blind: the file may or may not stay valid.
std::string truncate(std::string& s, Rng& rng) {
  s.resize(below(rng, s.size()));
  return "truncated to " + std::to_string(s.size()) + " bytes";
}

std::string flip_bytes(std::string& s, Rng& rng) {
  std::size_t n = 1 + below(rng, 8);
  for (std::size_t i = 0; i < n && !s.empty(); ++i) s[below(rng, s.size())] = static_cast<char>(below(rng, 256));
  return std::to_string(n) + " bytes replaced";
}

std::string flip_bits(std::string& s, Rng& rng) {
  std::size_t n = 1 + below(rng, 4);
  for (std::size_t i = 0; i < n && !s.empty(); ++i) s[below(rng, s.size())] ^= static_cast<char>(1 << below(rng, 8));
  return std::to_string(n) + " bits flipped";
}

std::string splice(std::string& s, Rng& rng) {
  std::size_t a = below(rng, s.size()), length = 1 + below(rng, std::min<std::size_t>(64, s.size() - a));
  if (below(rng, 2) == 0) {
    s.erase(a, length);
    return "deleted " + std::to_string(length) + " bytes at " + std::to_string(a);
  }
  s.insert(below(rng, s.size() + 1), s.substr(a, length));
  return "copied " + std::to_string(length) + " bytes from " + std::to_string(a);
}

std::string repeat_line(std::string& s, Rng& rng) {
  std::size_t lines = 1 + static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
  auto span = line_span(s, below(rng, lines));
  std::size_t times = std::size_t{1} << below(rng, 14);  // 1 .. 8192
  std::string line = s.substr(span.first, span.second - span.first) + "\n";
  std::string copies;
  for (std::size_t i = 0; i < times; ++i) copies += line;
  s.insert(span.first, copies);
  return "a line repeated " + std::to_string(times) + " times";
}

std::string swap_number(std::string& s, Rng& rng) {
  auto spans = numbers(s);
  if (spans.empty()) return flip_bytes(s, rng);
  auto span = spans[below(rng, spans.size())];
  std::string value = pick(rng, kSpecialNumbers);
  std::string was = s.substr(span.first, span.second - span.first);
  replace(s, span, value);
  return "number " + was + " := " + value;
}

std::string binary_field(std::string& s, Rng& rng) {
  std::size_t at = below(rng, s.size()) & ~std::size_t{3};
  if (below(rng, 2) == 0) {
    const std::uint32_t counts[] = {0xFFFFFFFFu, 0x7FFFFFFFu, 0x80000000u, 0x10000000u, 0u, 0xFFFFu};
    std::uint32_t value = pick(rng, counts);
    store(s, at, value);
    return "u32 at " + std::to_string(at) + " := " + std::to_string(value);
  }
  const float floats[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 1e30f, -3e38f,
                          1e-40f};
  float value = pick(rng, floats);
  store(s, at, value);
  return "f32 at " + std::to_string(at) + " := " + std::to_string(value);
}

// A space, tab or line end swapped for another character that separates
// words somewhere: readers disagree on which do (a header check that took a
// vertical tab for a space passed a header its reader never ended).
std::string swap_separator(std::string& s, Rng& rng) {
  const std::string spaces = " \t\n\r";
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (spaces.find(s[i]) != std::string::npos) at.push_back(i);
  if (at.empty()) return flip_bytes(s, rng);
  const char separators[] = {' ', '\t', '\n', '\r', '\v', '\f', '\0'};
  std::size_t i = at[below(rng, at.size())];
  s[i] = pick(rng, separators);
  return "separator at byte " + std::to_string(i) + " := " + std::to_string(static_cast<int>(s[i]));
}

std::string blind(const Seed& seed, std::string& s, Rng& rng) {
  if (s.empty()) return "empty";
  bool binary = !seed.float_offsets.empty();
  switch (below(rng, binary ? 9 : 8)) {
    case 0: return truncate(s, rng);
    case 1: return flip_bytes(s, rng);
    case 2: return flip_bits(s, rng);
    case 3: return splice(s, rng);
    case 4: return repeat_line(s, rng);
    case 5:
    case 6: return swap_number(s, rng);
    case 7: return swap_separator(s, rng);
    default: return binary_field(s, rng);
  }
}

}  // namespace

Case mutate(const Seed& seed, Rng& rng) {
  Case c{seed.format, seed.extension, seed.bytes, "", false};
  bool json = seed.format == "json" || seed.format == "gltf";
  bool can_poison = !seed.vertex_lines.empty() || !seed.float_offsets.empty();
  if (below(rng, 4) == 0 && (can_poison || json)) {
    if (json) {
      c.mutations = deep_nesting(c.bytes, rng);
      c.must_fail = seed.format == "json";  // our reader refuses depth > 64; glTF's may accept
    } else if (below(rng, 2) == 1 && !seed.face_lines.empty()) {
      c.mutations = bad_index(seed, c.bytes, rng);
      c.must_fail = true;
    } else {
      c.mutations = poison_vertex(seed, c.bytes, rng);
      c.must_fail = true;
    }
    return c;
  }
  std::size_t n = 1 + below(rng, 3);
  for (std::size_t i = 0; i < n; ++i) c.mutations += (i ? "; " : "") + blind(seed, c.bytes, rng);
  return c;
}

}  // namespace sh::fuzz
