// The DSL intersector agrees with Embree 3 on 100 000 random rays per
// built-in scene: same triangle and t within 1e-4 relative, except where
// two triangles tie, a ray grazes an edge (the two tests round differently
// there), or a ray starts within rounding of a surface.
#include <gtest/gtest.h>

#include <algorithm>

#include <embree_scene.hpp>

#include "helpers.hpp"

namespace {

class IntersectorAgainstEmbree : public testing::TestWithParam<rt_test::Walked> {
 public:
  void expect_agreement(const sh::rt::Scene& scene, std::size_t n, unsigned seed) {
    rt_test::Rays rays = rt_test::random_rays(scene, n, seed);
    rt_test::Hits hits = rt_test::trace(scene, rays, "cpu", GetParam());
    rt_test::Agreement a = rt_test::compare_with_embree(scene, rays, hits);
    std::size_t bad = a.unexplained();
    std::string detail;
    for (const std::string& d : a.disagreements) detail += "\n  " + d;
    EXPECT_EQ(bad, 0u) << scene.name << ": " << bad << " of " << a.rays << " rays disagree with Embree" << detail;
    EXPECT_GT(a.agree, a.rays / 4) << "too few rays hit anything to mean much";
    testing::Test::RecordProperty("ties", static_cast<int>(a.ties));
    testing::Test::RecordProperty("edge_grazes", static_cast<int>(a.edge_grazes));
  }
};

TEST_P(IntersectorAgainstEmbree, Cornell) { expect_agreement(sh::rt::builtin_scene("cornell"), 100000, 1); }
TEST_P(IntersectorAgainstEmbree, Spheres) { expect_agreement(sh::rt::builtin_scene("spheres"), 100000, 2); }
TEST_P(IntersectorAgainstEmbree, Procedural) { expect_agreement(sh::rt::builtin_scene("procedural", 20000), 100000, 3); }

INSTANTIATE_TEST_SUITE_P(Accelerators, IntersectorAgainstEmbree, testing::ValuesIn(rt_test::every_accelerator()),
                         [](const auto& info) {
                           std::string n = info.param.name();
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

// The benchmarks' Embree anchor traces packets: they must find what single
// rays find, a partly filled last packet included.
TEST(EmbreeAnchor, PacketsFindWhatSingleRaysFind) {
  sh::rt::Scene scene = sh::rt::builtin_scene("spheres");
  sh::rt::EmbreeScene embree(scene, "threads=1");
  rt_test::Rays rays = rt_test::random_rays(scene, 1003, 4);
  std::size_t n = rays.origins.size() / 3, hits = 0;
  for (int packet : {4, 8, 16}) {
    if (!embree.supports_packet(packet)) continue;
    for (std::size_t i = 0; i < n; i += static_cast<std::size_t>(packet)) {
      int count = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(packet), n - i)), found[16];
      embree.intersect_packet(packet, count, &rays.origins[3 * i], &rays.directions[3 * i], found);
      for (int j = 0; j < count; ++j) {
        RTCRayHit single = embree.intersect(rays.origin(i + j), rays.direction(i + j));
        int expected = single.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int>(single.hit.primID);
        ASSERT_EQ(found[j], expected) << "ray " << i + j << ", packets of " << packet;
        hits += expected >= 0;
      }
    }
  }
  EXPECT_GT(hits, 0u);
}

// A configuration Embree refuses is an error naming it, not a device that
// is not there.
TEST(EmbreeAnchor, ARefusedConfigurationIsAnError) {
  sh::rt::Scene scene = sh::rt::builtin_scene("cornell");
  try {
    sh::rt::EmbreeScene embree(scene, "threads=x");
    FAIL() << "Embree took threads=x";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("Embree: no device for the configuration \"threads=x\""), std::string::npos)
        << e.what();
  }
}

TEST(Grid, TriangleBoxOverlapIsExact) {
  using sh::rt::Vec3;
  Vec3 lo{0, 0, 0}, hi{1, 1, 1};
  EXPECT_TRUE(sh::rt::triangle_overlaps_box({0.5f, 0.5f, 0.5f}, {2, 0.5f, 0.5f}, {0.5f, 2, 0.5f}, lo, hi));
  // Bounding boxes overlap, the triangle passes beside the corner.
  EXPECT_FALSE(sh::rt::triangle_overlaps_box({1.2f, -0.5f, 0.5f}, {2, 0.5f, 0.5f}, {1.2f, 1.5f, 0.5f}, lo, hi));
  // Bounding boxes touch at the corner; the triangle's plane separates them.
  EXPECT_FALSE(sh::rt::triangle_overlaps_box({1.2f, 1, 1}, {1, 1.2f, 1}, {1, 1, 1.2f}, lo, hi));
  // A large triangle cutting through the box with no vertex inside.
  EXPECT_TRUE(sh::rt::triangle_overlaps_box({-5, -5, 0.5f}, {5, -5, 0.5f}, {0, 5, 0.5f}, lo, hi));
  // Touching a face counts.
  EXPECT_TRUE(sh::rt::triangle_overlaps_box({1, 0, 0}, {1, 1, 0}, {1, 0, 1}, lo, hi));
}

TEST(Grid, EveryTriangleIsListedWhereItLies) {
  sh::rt::Scene s = sh::rt::builtin_scene("cornell");
  sh::rt::Grid g = sh::rt::build_grid(s);
  std::vector<bool> seen(s.mesh.triangles(), false);
  for (std::int32_t t : g.cell_triangles)
    if (t >= 0) seen[t] = true;
  for (std::size_t t = 0; t < seen.size(); ++t) EXPECT_TRUE(seen[t]) << "triangle " << t;
  EXPECT_GT(g.cells(), s.mesh.triangles() / 4);
}

}  // namespace
