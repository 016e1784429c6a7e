// sh::opencl::RunDetails: the bytes runs moved between host and device.
#include <cstdio>

#include "sh/opencl.hpp"

namespace sh::opencl {

std::unique_ptr<sh::RunDetails> RunDetails::clone() const { return std::make_unique<RunDetails>(*this); }

void RunDetails::add(const sh::RunDetails& more) {
  auto* m = dynamic_cast<const RunDetails*>(&more);
  if (!m) return;
  runs += m->runs;
  to_device += m->to_device;
  from_device += m->from_device;
  in_place += m->in_place;
  tables_kept += m->tables_kept;
  tables_held = m->tables_held;
}

std::vector<std::string> RunDetails::describe() const {
  constexpr double kMiB = 1024.0 * 1024.0;
  char line[320];
  std::snprintf(line, sizeof line,
                "%zu runs moved %.2f MiB to the device and %.2f MiB back; %.2f MiB of streams used in place, %.2f MiB of "
                "tables already on the device; %.2f MiB of tables held there",
                runs, to_device / kMiB, from_device / kMiB, in_place / kMiB, tables_kept / kMiB, tables_held / kMiB);
  return {line};
}

}  // namespace sh::opencl
