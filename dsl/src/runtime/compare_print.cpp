// The text form of sh::compare's table: one line per row and output, the
// row's own columns on its first output's line only.
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

std::string milliseconds(const CompareRow& r, double ms, bool compile) {
  if (compile && !r.compiled) return "cached";
  return format("%.1f", ms);
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

std::string line(const std::string& label, const std::string& math, const std::string& compile, const std::string& run,
                 const std::string& rest) {
  char text[160];
  std::snprintf(text, sizeof text, "%-20s %-8s %10s %10s  ", label.c_str(), math.c_str(), compile.c_str(), run.c_str());
  return text + rest + "\n";
}

std::string output_columns(const OutputDifference& d) {
  char text[200];
  std::string worst = d.differing ? std::to_string(d.worst_element) : "-";
  std::snprintf(text, sizeof text, "%-10s %-7s %11s %10s %15s %8s", d.name.c_str(), ir::type_name(d.type).c_str(),
                magnitude(d.max_abs).c_str(), ulps(d.max_ulps).c_str(), differing(d).c_str(), worst.c_str());
  return text;
}

// An error's lines after the first, indented under it.
std::string indented(const std::string& message) {
  std::string out;
  for (char ch : message) out += ch == '\n' ? std::string("\n      ") : std::string(1, ch);
  return out;
}

std::string row_text(const CompareRow& r, bool reference_failed) {
  std::string label = r.label(), math = math_name(r.math);
  if (r.failed()) return line(label, math, "-", "-", "error: " + indented(r.error));
  std::string compile = milliseconds(r, r.compile_ms, true), run = milliseconds(r, r.run_ms, false);
  std::string text;
  if (r.outputs.empty())
    text = line(label, math, compile, run, reference_failed ? "(no reference to compare with)" : "(no outputs)");
  for (std::size_t k = 0; k < r.outputs.size(); ++k)
    text += k == 0 ? line(label, math, compile, run, output_columns(r.outputs[k])) : line("", "", "", "", output_columns(r.outputs[k]));
  for (const std::string& note : r.notes) text += "    " + note + "\n";
  return text;
}

}  // namespace

std::string to_string(const Comparison& c) {
  const CompareRow& ref = c.reference;
  std::string precision = c.rows.empty() || c.rows[0].precision == Precision::F32 ? "f32" : "f64";
  std::string text = "compare '" + c.program + "': " + std::to_string(c.elements) + " elements in " + precision +
                     " against interp in f64 ";
  text += ref.failed() ? "(failed: " + indented(ref.error) + ")\n"
                       : "(compile " + milliseconds(ref, ref.compile_ms, true) + " ms, run " + format("%.1f", ref.run_ms) + " ms)\n";
  char columns[200];
  std::snprintf(columns, sizeof columns, "%-10s %-7s %11s %10s %15s %8s", "output", "type", "max |diff|", "max ULPs",
                "differing", "worst at");
  text += line("backend", "math", "compile ms", "run ms", columns);
  for (const CompareRow& r : c.rows) text += row_text(r, ref.failed());
  return text;
}

std::ostream& operator<<(std::ostream& os, const Comparison& c) { return os << to_string(c); }

}  // namespace sh
