// Tables of each dimension, read by integer coordinates and by [0, 1]
// coordinates; reads outside clamp to the edge, whatever the coordinate.
#include "harness.hpp"

namespace conformance {
namespace {

int clampi(long long v, int n) { return static_cast<int>(std::min<long long>(std::max<long long>(v, 0), n - 1)); }

TEST_P(Conformance, Table1DFetchAndSampleClampToEdge) {
  sh::Table1D<sh::Attrib2f> t(5);
  std::vector<float> data;
  for (int i = 0; i < 5; ++i) {
    data.push_back(10.f * i);
    data.push_back(-1.f * i);
  }
  t.assign(data);
  sh::Program p = SH_BEGIN_PROGRAM("table1d") {
    sh::Input<sh::Attrib1i> i;
    sh::Input<sh::Attrib1f> u;
    sh::Output<sh::Attrib2f> fetched, sampled;
    fetched = t[i];
    sampled = t(u);
  } SH_END;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<std::int32_t> is = {0, 1, 4, 5, -1, 1000000, std::numeric_limits<std::int32_t>::min(), 2, 3};
  std::vector<float> us = {0.f, 0.1f, 0.2f, 0.99f, 1.f, -0.5f, nan, inf, -inf};
  sh::Channel<sh::Attrib1i> ci(is);
  sh::Channel<sh::Attrib1f> cu(us);
  sh::Channel<sh::Attrib2f> fetched, sampled;
  run(p, {ci, cu}, {fetched, sampled});
  for (std::size_t k = 0; k < is.size(); ++k) {
    int e = clampi(is[k], 5);
    EXPECT_EQ(fetched[2 * k], 10.f * e) << "fetch " << is[k];
    float u = us[k];
    if (fast() && !std::isfinite(u)) continue;
    float scaled = u * 5.f;
    long long s = std::isnan(scaled) ? 0 : scaled >= 2147483647.f ? 2147483647 : scaled <= -2147483648.f ? -2147483648LL : static_cast<long long>(std::floor(scaled));
    EXPECT_EQ(sampled[2 * k + 1], -1.f * clampi(s, 5)) << "sample " << u;
  }
}

TEST_P(Conformance, Table2DAnd3DFetch) {
  sh::Table2D<sh::Attrib1f> t2(4, 3);
  sh::Table3D<sh::Attrib1i> t3(2, 3, 4);
  std::vector<float> d2;
  for (int i = 0; i < 12; ++i) d2.push_back(static_cast<float>(i));
  std::vector<std::int32_t> d3;
  for (int i = 0; i < 24; ++i) d3.push_back(100 + i);
  t2.assign(d2);
  t3.assign(d3);
  sh::Program p = SH_BEGIN_PROGRAM("tables") {
    sh::Input<sh::Attrib3i> c;
    sh::Input<sh::Attrib2f> uv;
    sh::Output<sh::Attrib1f> a, s;
    sh::Output<sh::Attrib1i> b;
    a = t2[c(0, 1)];
    b = t3[c];
    s = t2(uv);
  } SH_END;
  std::vector<std::int32_t> cs = {0, 0, 0, 1, 2, 3, 3, 1, 2, -1, 9, 9, 1, 0, 1};
  std::vector<float> uvs = {0.f, 0.f, 0.5f, 0.5f, 0.9f, 0.4f, 2.f, -1.f, 0.3f, 0.99f};
  sh::Channel<sh::Attrib3i> cc(cs);
  sh::Channel<sh::Attrib2f> cuv(uvs);
  sh::Channel<sh::Attrib1f> a, s;
  sh::Channel<sh::Attrib1i> b;
  run(p, {cc, cuv}, {a, s, b});
  for (std::size_t k = 0; k < cs.size() / 3; ++k) {
    int x = cs[3 * k], y = cs[3 * k + 1], z = cs[3 * k + 2];
    EXPECT_EQ(a[k], static_cast<float>(clampi(x, 4) + 4 * clampi(y, 3)));
    EXPECT_EQ(b[k], 100 + clampi(x, 2) + 2 * (clampi(y, 3) + 3 * clampi(z, 4)));
    int sx = clampi(static_cast<long long>(std::floor(uvs[2 * k] * 4.f)), 4);
    int sy = clampi(static_cast<long long>(std::floor(uvs[2 * k + 1] * 3.f)), 3);
    EXPECT_EQ(s[k], static_cast<float>(sx + 4 * sy));
  }
}

TEST_P(Conformance, DataDependentLoopOverTable) {
  // A linked walk: each element names the next, -1 ends it.
  sh::Table1D<sh::Attrib2f> links(6);
  links.assign({3, 1.5f, -1, 2.f, 5, 4.f, 1, 8.f, 0, 16.f, -1, 32.f});
  sh::Program p = SH_BEGIN_PROGRAM("walk") {
    sh::Input<sh::Attrib1f> start;
    sh::Output<sh::Attrib1f> total;
    sh::Attrib1f at = start;
    total = 0.0f;
    SH_WHILE(at > -1.0f) {
      sh::Attrib2f node = links[at];
      total += node(1);
      at = node(0);
    } SH_ENDWHILE;
  } SH_END;
  sh::Channel<sh::Attrib1f> in(std::vector<float>{0, 2, 1, 5, 4}), out;
  run(p, {in}, {out});
  std::vector<float> want = {1.5f + 8.f + 2.f, 4.f + 32.f, 2.f, 32.f, 16.f + 1.5f + 8.f + 2.f};
  for (std::size_t k = 0; k < want.size(); ++k) EXPECT_EQ(out[k], want[k]) << "start " << in[k];
}

}  // namespace
}  // namespace conformance
