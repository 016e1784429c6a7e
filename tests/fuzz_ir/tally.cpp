#include "tally.hpp"

#include <cstdio>
#include <sstream>

namespace fuzz_ir {
namespace {

void add(std::map<std::string, std::size_t>& to, const std::map<std::string, std::size_t>& from) {
  for (const auto& [name, n] : from) to[name] += n;
}

std::string counts(const std::map<std::string, std::size_t>& m) {
  std::string out;
  for (const auto& [name, n] : m) out += (out.empty() ? "" : ", ") + name + " " + std::to_string(n);
  return out.empty() ? "none" : out;
}

}  // namespace

Tally& Tally::operator+=(const Tally& more) {
  programs += more.programs;
  runs += more.runs;
  disagreements += more.disagreements;
  failing_programs += more.failing_programs;
  invalid += more.invalid;
  accumulator_only += more.accumulator_only;
  crashes += more.crashes;
  hangs += more.hangs;
  add(by_mode, more.by_mode);
  add(by_backend, more.by_backend);
  add(by_operations, more.by_operations);
  return *this;
}

std::string Tally::line() const {
  std::ostringstream out;
  out << "tally " << programs << " " << runs << " " << disagreements << " " << failing_programs << " " << invalid << " "
      << accumulator_only << " " << crashes << " " << hangs;
  for (const auto& [tag, map] : {std::pair{'m', &by_mode}, std::pair{'b', &by_backend}, std::pair{'o', &by_operations}})
    for (const auto& [name, n] : *map) out << " " << tag << " " << name << " " << n;
  return out.str();
}

Tally Tally::parse(const std::string& line) {
  Tally t;
  std::istringstream in(line);
  std::string word;
  in >> word >> t.programs >> t.runs >> t.disagreements >> t.failing_programs >> t.invalid >> t.accumulator_only >> t.crashes >>
      t.hangs;
  std::string name;
  std::size_t n = 0;
  for (char tag; in >> tag >> name >> n;)
    (tag == 'm' ? t.by_mode : tag == 'b' ? t.by_backend : t.by_operations)[name] += n;
  return in.eof() ? t : Tally{};
}

void print_summary(const Tally& t, unsigned long long seed, double seconds) {
  std::printf("fuzz_ir: %zu programs, %zu runs, %zu disagreements in %zu programs, %zu invalid programs; seed %llu; %.0f s\n",
              t.programs, t.runs, t.disagreements, t.failing_programs, t.invalid, seed, seconds);
  std::printf("  of the disagreements: %zu crashes, %zu hangs, %zu in accumulator sums only\n", t.crashes, t.hangs,
              t.accumulator_only);
  std::printf("  by backend: %s\n  by mode: %s\n", counts(t.by_backend).c_str(), counts(t.by_mode).c_str());
  if (!t.by_operations.empty()) std::printf("  minimised, by operations kept: %s\n", counts(t.by_operations).c_str());
  std::fflush(stdout);
}

}  // namespace fuzz_ir
