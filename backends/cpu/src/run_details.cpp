// sh::cpu::RunDetails: which runs wrote their outputs past the cache.
#include "sh/cpu.hpp"

namespace sh::cpu {

std::unique_ptr<sh::RunDetails> RunDetails::clone() const { return std::make_unique<RunDetails>(*this); }

void RunDetails::add(const sh::RunDetails& more) {
  auto* m = dynamic_cast<const RunDetails*>(&more);
  if (!m) return;
  runs += m->runs;
  streamed += m->streamed;
}

std::vector<std::string> RunDetails::describe() const {
  if (streamed == 0) return {};
  return {std::to_string(streamed) + " of " + std::to_string(runs) + " runs wrote their outputs past the cache"};
}

}  // namespace sh::cpu
