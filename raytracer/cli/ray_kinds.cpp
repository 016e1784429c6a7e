#include "ray_kinds.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "backend_compare.hpp"
#include "embree_anchor.hpp"
#include "hand_walk.hpp"

namespace shtrace {
namespace {

using sh::rt::Vec3;

void add(RayBatch& b, Vec3 o, Vec3 d, float t_near, float t_far) {
  b.origins.insert(b.origins.end(), {o.x, o.y, o.z});
  b.directions.insert(b.directions.end(), {d.x, d.y, d.z});
  b.t_near.push_back(t_near);
  b.t_far.push_back(t_far);
}

// Where shadow rays go: the first point light, else the first disk light's
// centre, else a point beyond the scene's upper corner.
Vec3 light_position(const sh::rt::Scene& s) {
  if (!s.lights.empty()) return s.lights[0].position;
  if (!s.disk_lights.empty()) return s.disk_lights[0].centre;
  return s.bounds_max() + (s.bounds_max() - s.bounds_min());
}

struct Kinds {
  RayBatch primary, shadow, reflection;
};

// From every camera ray's hit: a shadow ray to the light and the mirror
// reflection about the triangle's plane, both from the hit point pushed off
// the plane to the side the ray goes (as the tracer's rays leave a
// surface), so the kernels and Embree start them at the same point.
Kinds make_rays(sh::rt::Renderer& r, const sh::BackendChoice& choice) {
  const sh::rt::Scene& s = r.scene();
  Kinds k;
  std::tie(k.primary.origins, k.primary.directions) = primary_rays(r, r.settings().width, r.settings().height);
  sh::rt::Hits hits = r.intersect(k.primary.origins, k.primary.directions, choice);
  float size = sh::rt::length(s.bounds_max() - s.bounds_min());
  Vec3 light = light_position(s);
  for (std::size_t i = 0; i < k.primary.size(); ++i) {
    if (hits.triangle[i] < 0) continue;
    Vec3 d = k.primary.direction(i), p = k.primary.origin(i) + d * hits.t[i];
    const Vec3* v = &s.mesh.positions[3 * static_cast<std::size_t>(hits.triangle[i])];
    Vec3 n = sh::rt::normalize(sh::rt::cross(v[1] - v[0], v[2] - v[0]));
    float clearance = 1e-5f * size + 1e-6f * std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    auto leave = [&](Vec3 towards) { return p + n * (sh::rt::dot(n, towards) < 0 ? -clearance : clearance); };
    Vec3 to_light = light - p;
    float distance = sh::rt::length(to_light);
    if (distance > 0) add(k.shadow, leave(to_light), to_light * (1 / distance), 0, distance);
    Vec3 mirrored = d - n * (2 * sh::rt::dot(d, n));
    add(k.reflection, leave(mirrored), mirrored, 0, INFINITY);
  }
  return k;
}

struct Rate {
  double mrays_per_s = 0;
  std::size_t hits = 0;
  std::vector<double> round_ms;  // each timed round's, in the order run
};

// The lowest and highest of `ours` against `theirs` round by round, as
// rates (their time over ours): a shared host's slow spells move single
// rounds, and the median alone hides how far.
std::pair<double, double> round_spread(const Rate& ours, const Rate& theirs) {
  double low = INFINITY, high = 0;
  for (std::size_t i = 0; i < std::min(ours.round_ms.size(), theirs.round_ms.size()); ++i) {
    double ratio = theirs.round_ms[i] / ours.round_ms[i];
    low = std::min(low, ratio);
    high = std::max(high, ratio);
  }
  return {high > 0 ? low : 0.0, high};
}

// One run of a contestant: its hits, and its time in `ms`.  An empty one
// (Embree's packets on a CPU without them) has no rate.
using Run = std::function<std::size_t(double& ms)>;

// The contestants' rates over the same rays, timed in interleaved rounds:
// each runs once untimed first (our kernels compile), then every round
// runs each once in turn, so that a slow spell of a shared host falls on
// all of them alike.  Each rate is of its median round.
std::vector<Rate> race(std::size_t rays, int rounds, const std::vector<Run>& runs) {
  std::vector<std::vector<double>> ms(runs.size());
  std::vector<Rate> rates(runs.size());
  for (int round = -1; round < rounds; ++round)
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (!runs[i]) continue;
      double took = 0;
      rates[i].hits = runs[i](took);
      if (round >= 0) ms[i].push_back(took);
    }
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (ms[i].empty()) continue;
    rates[i].round_ms = ms[i];
    auto middle = ms[i].begin() + static_cast<std::ptrdiff_t>(ms[i].size() / 2);
    std::nth_element(ms[i].begin(), middle, ms[i].end());
    rates[i].mrays_per_s = static_cast<double>(rays) / (*middle * 1e3);
  }
  return rates;
}

// Embree's pass as a contestant.
Run embree_run(const sh::rt::EmbreeScene& embree, const RayBatch& b, int packet, Query q) {
  auto pass = std::make_shared<EmbreePass>(embree, b, packet, q);
  if (!pass->supported()) return {};
  return [pass](double& ms) {
    auto t0 = std::chrono::steady_clock::now();
    std::size_t hits = pass->run();
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return hits;
  };
}

std::size_t count_hits(const std::vector<float>& blocked) {
  std::size_t n = 0;
  for (float b : blocked) n += b > 0;
  return n;
}

std::size_t count_hits(const std::vector<std::int32_t>& triangles) {
  std::size_t n = 0;
  for (std::int32_t t : triangles) n += t >= 0;
  return n;
}

void print_row(const char* kind, std::size_t rays, const Rate& ours, const std::string& embree_call, const Rate& one,
               const Rate& packets) {
  auto [low, high] = round_spread(ours, one);
  std::printf("%-25s %8zu %9.2f %8zu   %-15s %8.2f %8.2f %8zu   %6.3fx %6.3fx   %.3f-%.3fx\n", kind, rays,
              ours.mrays_per_s, ours.hits, embree_call.c_str(), one.mrays_per_s, packets.mrays_per_s, one.hits,
              ours.mrays_per_s / one.mrays_per_s, packets.mrays_per_s > 0 ? ours.mrays_per_s / packets.mrays_per_s : 0.0,
              low, high);
}

// The accelerator's build beside Embree's of the same triangles (on as
// many threads).
void print_builds(const sh::rt::Renderer& r, const sh::rt::EmbreeScene& embree) {
  std::size_t n = r.scene().mesh.triangles();
  std::printf("build: %s %.1f ms, %.1f bytes per triangle (+ 36 of vertices in the scene's tables); Embree %.1f ms, "
              "%.1f bytes per triangle (its 48 of vertices and indices included)\n",
              sh::rt::accel_name(r.accel()), r.accelerator_build_ms(), static_cast<double>(r.accelerator_bytes()) / n,
              embree.build_ms(), static_cast<double>(embree.bytes()) / n);
}

// How the kernels' answers compare with the hand-written walk's (`what`
// each ray's is), as a sentence's end.  The walk computes as precise f32
// kernels do: other kernels may rightly answer otherwise where rounding
// decides.
std::string agreement(const std::vector<std::int32_t>& ours, const std::vector<std::int32_t>& hand, const char* what,
                      const sh::Options& options) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(ours.size(), hand.size()); ++i) differ += ours[i] != hand[i];
  if (differ == 0 && ours.size() == hand.size()) return std::string("the same ") + what + " on every ray";
  std::string said = "a different " + std::string(what) + " on " + std::to_string(differ) + " of " +
                     std::to_string(std::max(ours.size(), hand.size())) + " rays";
  if (options.precision != sh::Precision::F32 || options.math != sh::MathMode::Precise)
    said += " (the kernels compute in " + std::string(options.precision == sh::Precision::F32 ? "f32" : "f64") +
            (options.math == sh::MathMode::Fast ? ", fast math" : "") + "; the C++ walk as precise f32 kernels)";
  return said;
}

// The hand-written walk's row beside Embree's, then the kernels against it
// (`rays` names the rays and their query).
void print_hand_walk(const std::string& kind, const std::string& rays, std::size_t count, const Rate& ours,
                     const Rate& hand, const std::string& embree_call, const Rate& one, const Rate& packets,
                     const std::string& agree) {
  print_row((kind + ", C++ walk").c_str(), count, hand, embree_call, one, packets);
  auto [low, high] = round_spread(ours, hand);
  std::printf("%s: the kernels are %.3fx the hand-written C++ walk of the same tree (%.3f-%.3fx by round); %s\n",
              rays.c_str(), ours.mrays_per_s / hand.mrays_per_s, low, high, agree.c_str());
}

// Whether each ray hit: 1 or 0.
std::vector<std::int32_t> hit_or_not(const std::vector<std::int32_t>& triangles) {
  std::vector<std::int32_t> out(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) out[i] = triangles[i] >= 0;
  return out;
}

std::vector<std::int32_t> hit_or_not(const std::vector<float>& blocked) {
  std::vector<std::int32_t> out(blocked.size());
  for (std::size_t i = 0; i < blocked.size(); ++i) out[i] = blocked[i] > 0;
  return out;
}

// One kind's lanes in the BVH's walk, the rays walked to `limits`.
void print_lanes(sh::rt::Renderer& r, const sh::BackendChoice& choice, const char* kind, const RayBatch& b,
                 const std::vector<float>& limits, bool any_hit) {
  sh::rt::WalkLanes l = r.walk_lanes(b.origins, b.directions, limits, any_hit, choice);
  std::printf("%-22s box steps %10lld, %5.1f %% the lane's own; leaf tests %9lld, %5.1f %% the lane's own\n", kind,
              static_cast<long long>(l.steps), 100 * l.box_share(), static_cast<long long>(l.leaves), 100 * l.leaf_share());
}

// Embree's device configuration: where the cpu backend traces for an
// x86-64 level (its setting "isa", which it has checked the host has),
// Embree runs that level's code too (the levels' names are Embree's), so
// that both sides use the same instructions.
std::string embree_config(const std::string& backend, const sh::Options& options) {
  if (backend != "cpu") return "";
  auto cpu = options.backends.find("cpu");
  if (cpu == options.backends.end()) return "";
  sh::Settings settings = cpu->second.settings();
  auto isa = settings.find("isa");
  return isa == settings.end() ? "" : "isa=" + isa->second;
}

}  // namespace

int compare_ray_kinds(const RayKindsRequest& request) {
  // A lazy octree's walks run in waves, which the occlusion kernel does not.
  if (request.settings.accel == sh::rt::Accel::LazyOctree)
    throw sh::Error("rays: a lazy octree's shadow rays run only inside the tracer's waves; use --accel grid, octree, "
                    "bvh or auto");
  sh::rt::Renderer r(request.scene, request.settings);
  if (request.lanes && r.accel() != sh::rt::Accel::Bvh)
    throw sh::Error(std::string("rays --lanes: lanes are counted in the BVH's walk, and the accelerator is the ") +
                    sh::rt::accel_name(r.accel()) + "; use --accel bvh");
  sh::BackendChoice choice = sh::backend(request.settings.backend, request.settings.options);
  Kinds k = make_rays(r, choice);
  const sh::rt::Scene& s = r.scene();
  std::string backend = choice.name.empty() ? sh::default_backend_name() : choice.name;
  std::string config = embree_config(backend, request.settings.options);
  sh::rt::EmbreeScene embree(s, config.c_str());
  int n = request.repeats;
  std::string embree_note = config.empty() ? "" : "; Embree with " + config;
  std::printf("scene %s: %zu triangles, %s; %s backend; %d rounds, each contestant once a round in turn, rates of "
              "the median round, \"/1 by round\" the lowest and highest of the rounds' own ratios%s\n",
              s.name.c_str(), s.mesh.triangles(), r.describe_accelerator().c_str(), backend.c_str(), n,
              embree_note.c_str());
  print_builds(r, embree);
  // The hand-written walk of the same tree, where it can walk it.
  std::optional<HandWalk> hand;
  if (HandWalk::walks(r))
    hand.emplace(*r.bvh());
  else
    std::printf("no hand-written C++ walk: it walks the BVH's wide layout, and the accelerator is the %s%s\n",
                sh::rt::accel_name(r.accel()),
                r.bvh() ? (std::string(" walked ") + sh::rt::bvh_walk_name(r.bvh()->walk)).c_str() : "");
  // Embree's widest packet this CPU runs natively (16 needs AVX-512, 8 AVX).
  int packet = 16;
  while (packet > 4 && !embree.supports_packet(packet)) packet /= 2;
  std::string wide = std::to_string(packet);
  std::printf("%-25s %8s %9s %8s   %-15s %8s %8s %8s   %7s %7s   %s\n", "rays", "count", "Mrays/s", "hits", "Embree",
              "1 ray", (wide + " rays").c_str(), "hits", "/1", ("/" + wide).c_str(), "/1 by round");
  // Our kernels as contestants: the run's own time, as RunStats has it;
  // each run's nearest triangles into `found`.
  auto nearest = [&](const RayBatch& b, std::vector<std::int32_t>& found) -> Run {
    return [&r, &choice, rays = &b, &found](double& ms) {
      sh::RunStats st;
      sh::rt::Hits hits = r.intersect(rays->origins, rays->directions, choice, &st);
      ms = st.run_ms;
      found = std::move(hits.triangle);
      return count_hits(found);
    };
  };
  auto hand_run = [&](const RayBatch& b, Query query, std::vector<std::int32_t>& found) -> Run {
    return [&hand, rays = &b, query, &found](double& ms) {
      auto t0 = std::chrono::steady_clock::now();
      std::size_t hits = hand->run(*rays, query, found);
      ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      return hits;
    };
  };
  auto occluded = [&](const RayBatch& b, bool any_hit, std::vector<float>& found) -> Run {
    return [&r, &choice, rays = &b, any_hit, &found](double& ms) {
      sh::RunStats st;
      found = r.occluded(rays->origins, rays->directions, rays->t_far, choice, any_hit, &st);
      ms = st.run_ms;
      return count_hits(found);
    };
  };
  auto against_embree = [&](const char* kind, const RayBatch& b, const sh::rt::EmbreeScene& e, bool with_hand) {
    std::vector<std::int32_t> ours_hit, hand_hit;
    std::vector<Run> runs = {nearest(b, ours_hit), embree_run(e, b, 1, Query::Nearest),
                             embree_run(e, b, packet, Query::Nearest)};
    if (with_hand && hand) runs.push_back(hand_run(b, Query::Nearest, hand_hit));
    std::vector<Rate> rate = race(b.size(), n, runs);
    print_row(kind, b.size(), rate[0], "rtcIntersect", rate[1], rate[2]);
    if (with_hand && hand)
      print_hand_walk(kind, kind + std::string(" rays"), b.size(), rate[0], rate[3], "rtcIntersect", rate[1], rate[2],
                      agreement(ours_hit, hand_hit, "nearest triangle", request.settings.options));
  };
  against_embree("camera", k.primary, embree, true);
  {
    // Embree is timed in its robust mode above, whose hits on edges and
    // vertices our walk's watertight test matches; its default mode is
    // faster, and a user who can lose such hits would compare with it.
    sh::rt::EmbreeScene fast(s, config.c_str(), false);
    against_embree("camera, Embree default", k.primary, fast, false);
  }
  if (k.reflection.size() == 0) {
    std::printf("no camera ray hits the scene: no shadow or reflection rays to trace\n");
    return 0;
  }
  // Each walk of the shadow rays against Embree's query of the same kind,
  // to the same limits, all in the same rounds.
  std::vector<float> any_blocked, nearest_blocked;
  std::vector<std::int32_t> hand_blocked;
  std::vector<Run> shadow_runs = {occluded(k.shadow, true, any_blocked), occluded(k.shadow, false, nearest_blocked),
                                  embree_run(embree, k.shadow, 1, Query::Any),
                                  embree_run(embree, k.shadow, packet, Query::Any),
                                  embree_run(embree, k.shadow, 1, Query::Nearest),
                                  embree_run(embree, k.shadow, packet, Query::Nearest)};
  if (hand) shadow_runs.push_back(hand_run(k.shadow, Query::Any, hand_blocked));
  std::vector<Rate> shadow = race(k.shadow.size(), n, shadow_runs);
  print_row("shadow, any hit", k.shadow.size(), shadow[0], "rtcOccluded", shadow[2], shadow[3]);
  if (hand)
    print_hand_walk("shadow, any hit", "shadow rays, any hit", k.shadow.size(), shadow[0], shadow[6], "rtcOccluded",
                    shadow[2], shadow[3],
                    agreement(hit_or_not(any_blocked), hit_or_not(hand_blocked), "answer (blocked or not)",
                              request.settings.options));
  print_row("shadow, nearest hit", k.shadow.size(), shadow[1], "rtcIntersect", shadow[4], shadow[5]);
  against_embree("reflection", k.reflection, embree, true);
  // What stopping at the first hit can buy on these rays: Embree's own
  // any-hit query against its nearest-hit one.
  auto [low, high] = round_spread(shadow[0], shadow[1]);
  std::printf("shadow rays: the any-hit walk is %.2fx as fast as the nearest-hit walk (%.2f-%.2fx by round; Embree: "
              "rtcOccluded1 %.2fx rtcIntersect1 on the same rays)\n",
              shadow[0].mrays_per_s / shadow[1].mrays_per_s, low, high, shadow[2].mrays_per_s / shadow[4].mrays_per_s);
  if (request.lanes) {
    // Camera and reflection rays walk to kFar, as their rows above do.
    std::printf("lanes in the BVH's walk (%d side by side):\n", sh::lanes_of(choice));
    print_lanes(r, choice, "camera", k.primary, std::vector<float>(k.primary.size(), sh::rt::kFar), false);
    print_lanes(r, choice, "shadow, any hit", k.shadow, k.shadow.t_far, true);
    print_lanes(r, choice, "shadow, nearest hit", k.shadow, k.shadow.t_far, false);
    print_lanes(r, choice, "reflection", k.reflection, std::vector<float>(k.reflection.size(), sh::rt::kFar), false);
  }
  return 0;
}

}  // namespace shtrace
