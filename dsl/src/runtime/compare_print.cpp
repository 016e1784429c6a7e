// The text form of sh::compare's table: one line per row and output, the
// row's own columns on its first output's line only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "sh/compare.hpp"

namespace sh {
namespace {

std::string format(const char* pattern, double v) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, v);
  return text;
}

// A compile column's time says "disk" where the machine code was loaded
// from the disk cache: a few ms, where compiling took a hundred.
std::string milliseconds(const CompareRow& r, double ms, bool compile) {
  if (compile && !r.compiled) return "cached";
  return format("%.1f", ms) + (compile && r.from_disk ? " disk" : "");
}

std::string magnitude(double v) {
  if (std::isinf(v)) return "inf";
  if (v == 0) return "0";
  return format("%.3g", v);
}

std::string ulps(double v) {
  if (std::isinf(v)) return "inf";
  return v < 1e7 ? format("%.0f", v) : format("%.3g", v);
}

std::string differing(const OutputDifference& d) {
  std::string text = std::to_string(d.differing);
  if (d.nan_mismatches > 0) text += " (" + std::to_string(d.nan_mismatches) + " NaN)";
  return text;
}

std::string math_name(MathMode m) { return m == MathMode::Fast ? "fast" : "precise"; }

// Columns of at least `width` characters; a longer text is kept whole and
// pushes the rest of its line along.
std::string left(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}
std::string right(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}

std::string line(const std::string& label, const std::string& math, const std::string& compile, const std::string& run,
                 const std::string& rest) {
  return left(label, 20) + " " + left(math, 8) + " " + right(compile, 10) + " " + right(run, 10) + "  " + rest + "\n";
}

// The output column is as wide as the longest name the table prints.
std::string output_columns(std::size_t name_width, const std::string& name, const std::string& type,
                           const std::string& max_abs, const std::string& max_ulps, const std::string& differing,
                           const std::string& worst) {
  return left(name, name_width) + " " + left(type, 7) + " " + right(max_abs, 11) + " " + right(max_ulps, 10) + " " +
         right(differing, 15) + " " + right(worst, 8);
}

std::string output_columns(std::size_t name_width, const OutputDifference& d) {
  std::string worst = d.differing ? std::to_string(d.worst_element) : "-";
  return output_columns(name_width, d.name, ir::type_name(d.type), magnitude(d.max_abs), ulps(d.max_ulps), differing(d),
                        worst);
}

// An error's lines after the first, indented under it.
std::string indented(const std::string& message) {
  std::string out;
  for (char ch : message) out += ch == '\n' ? std::string("\n      ") : std::string(1, ch);
  return out;
}

std::string row_text(const CompareRow& r, bool reference_failed, std::size_t name_width) {
  std::string label = r.label(), math = math_name(r.math);
  if (r.failed()) return line(label, math, "-", "-", "error: " + indented(r.error));
  std::string compile = milliseconds(r, r.compile_ms, true), run = milliseconds(r, r.run_ms, false);
  std::string text;
  if (r.outputs.empty())
    text = line(label, math, compile, run, reference_failed ? "(no reference to compare with)" : "(no outputs)");
  for (std::size_t k = 0; k < r.outputs.size(); ++k)
    text += line(k == 0 ? label : "", k == 0 ? math : "", k == 0 ? compile : "", k == 0 ? run : "",
                 output_columns(name_width, r.outputs[k]));
  for (const std::string& note : r.notes) text += "    " + note + "\n";
  return text;
}

}  // namespace

std::string to_string(const Comparison& c) {
  const CompareRow& ref = c.reference;
  std::string precision = c.precision == Precision::F32 ? "f32" : "f64";
  std::string text = "compare '" + c.program + "': " + std::to_string(c.elements) + " elements in " + precision +
                     " against interp in f64 ";
  text += ref.failed() ? "(failed: " + indented(ref.error) + ")\n"
                       : "(compile " + milliseconds(ref, ref.compile_ms, true) + " ms, run " + format("%.1f", ref.run_ms) + " ms)\n";
  std::size_t name_width = 10;
  for (const CompareRow& r : c.rows)
    for (const OutputDifference& d : r.outputs) name_width = std::max(name_width, d.name.size());
  text += line("backend", "math", "compile ms", "run ms",
               output_columns(name_width, "output", "type", "max |diff|", "max ULPs", "differing", "worst at"));
  for (const CompareRow& r : c.rows) text += row_text(r, ref.failed(), name_width);
  return text;
}

std::ostream& operator<<(std::ostream& os, const Comparison& c) { return os << to_string(c); }

}  // namespace sh
