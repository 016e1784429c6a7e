// Prefetches: a hint, so every backend gives the results it gives without
// them, at coordinates inside and far outside the table (legal IR leaves
// them as asked; no backend faults), in lanes that differ and lanes that agree, under a
// divergent branch, and in a walk that asks for the next link before it
// follows it.
#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1i;
using sh::Attrib3f;
using sh::ConstAttrib1i;

constexpr int kNodes = 37;
int next_node(int k) { return (k * 5 + 3) % kNodes; }

TEST_P(Conformance, PrefetchChangesNoResultAtAnyCoordinates) {
  sh::Table1D<Attrib3f> values(kNodes);
  sh::Table2D<Attrib1i> links(kNodes, 2);  // row 0: the next node; row 1: unread
  std::vector<float> v;
  std::vector<std::int32_t> l(2 * kNodes, -7);
  for (int k = 0; k < kNodes; ++k) {
    v.insert(v.end(), {static_cast<float>(k), -static_cast<float>(k), 0.5f * static_cast<float>(k)});
    l[static_cast<std::size_t>(k)] = next_node(k);
  }
  values.assign(v);
  links.assign(l);
  sh::Program p = SH_BEGIN_PROGRAM("prefetches") {
    sh::Input<Attrib1i> i;
    sh::Output<Attrib3f> r;
    sh::Output<Attrib1i> steps;
    values.prefetch(i);
    values.prefetch(i * 100000 - 2000000000);
    values.prefetch(2147483647);
    links.prefetch(join(-i, i + 5));
    r = values[i];
    SH_IF(i > 20) {
      values.prefetch(-i);
      r += values[i + 1];
    } SH_ENDIF;
    Attrib1i node = max(i, 0) % kNodes;
    steps = 0;
    SH_WHILE(node != 0 && steps < 50) {
      Attrib1i next = links[join(node, ConstAttrib1i(0))];
      links.prefetch(join(next, ConstAttrib1i(0)));
      values.prefetch(next);
      node = next;
      steps += 1;
    } SH_ENDWHILE;
    r(2) += values[node](2);
  } SH_END;
  std::vector<std::int32_t> is;
  for (int k = -40; k < 1000; ++k) is.push_back(k);
  sh::Channel<Attrib1i> ci(is);
  sh::Channel<Attrib3f> r;
  sh::Channel<Attrib1i> steps;
  run(p, {ci}, {r, steps});
  auto at = [&](int k) { return std::min(std::max(k, 0), kNodes - 1); };
  for (std::size_t e = 0; e < is.size(); ++e) {
    int i = is[e];
    float want_x = static_cast<float>(at(i)) + (i > 20 ? static_cast<float>(at(i + 1)) : 0.f);
    int node = std::max(i, 0) % kNodes, walked = 0;
    while (node != 0 && walked < 50) node = next_node(node), ++walked;
    float want_z = 0.5f * static_cast<float>(at(i)) + (i > 20 ? 0.5f * static_cast<float>(at(i + 1)) : 0.f) +
                   0.5f * static_cast<float>(node);
    EXPECT_EQ(r[3 * e], want_x) << "element " << i;
    EXPECT_EQ(r[3 * e + 2], want_z) << "element " << i;
    EXPECT_EQ(steps[e], walked) << "element " << i;
  }
}

}  // namespace
}  // namespace conformance
