// The light pass (bidirectional.hpp): one stream element per ray, from a
// light to a sample point of an element; energy left by scatter-add.
#include <algorithm>
#include <cstdint>
#include <map>
#include <tuple>

#include "elements.hpp"
#include "sh/error.hpp"
#include "sh/raytracer/accelerator.hpp"
#include "sh/raytracer/bidirectional.hpp"
#include "sh/raytracer/solid_angle.hpp"
#include "shading.hpp"

namespace sh::rt {
namespace {

// Sample point k of n inside a triangle, as weights of its second and
// third corners: the R2 low-discrepancy sequence mapped by the
// area-preserving square-root map, which keeps every point off the edges
// (a point on an edge may hit the neighbour).  The same points on every
// backend, no random state.
Attrib2f sample_in_triangle(const Attrib1i& k) {
  Attrib1f x = k.cast<float>();
  Attrib2f r = frac(0.5f + x * ConstAttrib2f(0.7548776662f, 0.5698402910f));
  Attrib1f root = sqrt(r(0));
  return join(root * (1.0f - r(1)), root * r(1));
}

Point3f lattice_point(const SceneTables& s, const Attrib1i& tri, const Attrib1f& i, const Attrib1f& j, const Attrib1f& k) {
  Attrib3f v0 = s.v0[tri];
  return v0 + (i * (s.v1[tri] - v0) + j * (s.v2[tri] - v0)) / k;
}

LightPassSettings checked(LightPassSettings settings, std::size_t triangles) {
  if (settings.subdivision < 1 || settings.subdivision > 64)
    throw Error("light pass: elements per triangle side must be 1..64, got " + std::to_string(settings.subdivision));
  // Kernels number element and lattice slots in 32 bits.
  int k = settings.subdivision;
  std::size_t slots = side_slot(triangles, 0, std::max(element_slots(k), lattice_slots(k)));
  if (slots > static_cast<std::size_t>(INT32_MAX))
    throw Error("light pass: " + std::to_string(triangles) + " triangles of " + std::to_string(k) + " x " +
                std::to_string(k) + " elements take " + std::to_string(slots) +
                " slots, more than a kernel numbers (2^31 - 1); use fewer elements per side");
  if (settings.samples < 1) throw Error("light pass: rays per element must be at least 1, got " + std::to_string(settings.samples));
  if (settings.depth < 0 || settings.depth > 64) throw Error("light pass: depth must be 0..64, got " + std::to_string(settings.depth));
  return settings;
}

}  // namespace

// The default: the area-weighted mean squared distance from the light to
// the scene's surfaces, so that they are lit on average as brightly as the
// direct tracer (which has no fall-off) lights them.
Vec3 light_intensity(const Scene& s, const PointLight& l) {
  double i = l.intensity;
  if (i <= 0) {
    double weighted = 0, area = 0;
    const std::vector<Vec3>& p = s.mesh.positions;
    for (std::size_t t = 0; t + 2 < p.size(); t += 3) {
      double a = 0.5 * length(cross(p[t + 1] - p[t], p[t + 2] - p[t]));
      Vec3 to = (p[t] + p[t + 1] + p[t + 2]) * (1.0f / 3) - l.position;
      weighted += a * dot(to, to);
      area += a;
    }
    i = area > 0 ? weighted / area : 1;
  }
  return l.color * static_cast<float>(i);
}

Vec3 ElementLight::total() const {
  Vec3 sum;
  for (std::size_t i = 0; i + 2 < energy.size(); i += 3) sum = sum + Vec3{energy[i], energy[i + 1], energy[i + 2]};
  return sum;
}

LightPass::LightPass(const Scene& scene, const SceneTables& tables, LightPassSettings settings)
    : lights_(scene.lights.size()),
      settings_(checked(settings, scene.mesh.triangles())),
      element_table_(static_cast<int>(std::max<std::size_t>(1, scene.mesh.triangles() * settings.subdivision * settings.subdivision))),
      emitters_(static_cast<int>(std::max<std::size_t>(2, 2 * scene.lights.size()))),  // one light's rows at least
      energy_(static_cast<int>(side_slot(scene.mesh.triangles(), 0, element_slots(settings.subdivision))), "element_energy") {
  if (tables.octree && tables.octree->lazy)
    throw Error("light pass: runs over a grid or a static octree (a lazy octree is built by the view's rays)");
  int k = settings.subdivision;
  for (std::size_t t = 0; t < scene.mesh.triangles(); ++t)
    for_each_element(k, [&](int i, int j, int down) {
      elements_.insert(elements_.end(), {static_cast<std::int32_t>(t), i, j, down});
    });
  element_table_.name("elements").assign(elements_);
  std::vector<float> emit;
  for (const PointLight& l : scene.lights) {
    Vec3 i = light_intensity(scene, l);
    emit.insert(emit.end(), {l.position.x, l.position.y, l.position.z, i.x, i.y, i.z});
  }
  emit.resize(std::max<std::size_t>(emit.size(), 6), 0.0f);
  emitters_.name("emitters").assign(emit);
  element_count_ = static_cast<std::int32_t>(elements_.size() / 4);
  sample_count_ = settings.samples;
  subdivision_ = static_cast<float>(k);
  depth_ = static_cast<float>(settings.depth);

  Features f = Features::of(scene, settings.depth);
  f.vertex_colors = false;
  const SceneTables& s = tables;
  program_ = SH_BEGIN_PROGRAM("light_pass") {
    InputAttrib1i ray;
    Attrib1i per_light = element_count_ * sample_count_;
    Attrib1i light = ray / per_light, element = (ray % per_light) / sample_count_, sample = ray % sample_count_;
    Attrib4i el = element_table_[element];
    Attrib1i target = el(0);
    Attrib1f i = el(1).cast<float>(), j = el(2).cast<float>();
    Attrib1f down = el(3).cast<float>();
    // Up element: (i, j), (i+1, j), (i, j+1); down: (i+1, j+1), (i, j+1), (i+1, j).
    Point3f a = lattice_point(s, target, i + down, j + down, subdivision_);
    Point3f b = lattice_point(s, target, i + 1.0f - down, j + down, subdivision_);
    Point3f c = lattice_point(s, target, i + down, j + 1.0f - down, subdivision_);
    Attrib2f r = sample_in_triangle(sample);
    Point3f from = emitters_[2 * light];
    Point3f to = a + r(0) * (b - a) + r(1) * (c - a);
    Color3f power = emitters_[2 * light + 1] * solid_angle(a - from, b - a, c - a) / sample_count_.cast<float>();
    Vector3f d = normalize(to - from);
    Point3f o = from;
    Intersector intersect(s);
    Attrib1f t;
    Attrib1i tri;
    Attrib2f uv;
    Attrib1f arrives = intersect(o, d, kFar, t, tri, uv) && (tri == target).cast<float>();
    auto leave_energy = [&](const Surface& x) {
      Attrib1i side = (kSides * tri + side_met(x.ng, d)) * element_slots(k);
      SH_IF(x.shaded() > 0.0f) { energy_.add(side + element_at(uv, subdivision_).slot, power); } SH_ENDIF;
    };
    if (f.reflections || f.refractions) {
      Attrib1f bounces = 0.0f;
      SH_WHILE(arrives) {
        Surface x = surface_at(s, d, tri, uv, f);
        leave_energy(x);
        Continuation next = go_on(x, d, f);
        power *= next.share;
        bounces += 1.0f;
        SH_BREAK(bounces > depth_ || max_component(power) <= 0.0f);
        o = next.o;
        d = next.d;
        arrives = intersect(o, d, kFar, t, tri, uv);
      } SH_ENDWHILE;
    } else {
      SH_IF(arrives) { leave_energy(surface_at(s, d, tri, uv, f)); } SH_ENDIF;
    }
  } SH_END;
}

std::vector<float> LightPass::run(const BackendChoice& choice, LightPassReport* report) {
  energy_.clear();
  std::size_t n = rays();
  if (n > static_cast<std::size_t>(INT32_MAX))
    throw Error("light pass: " + std::to_string(n) + " rays are more than one stream holds; use fewer elements or samples");
  LightPassReport r;
  r.rays = n;
  // In slices, so that no stream of ray numbers is the whole pass.
  constexpr std::size_t kSlice = 1 << 20;
  for (std::size_t first = 0; first < n; first += kSlice) {
    std::vector<std::int32_t> ids(std::min(kSlice, n - first));
    for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<std::int32_t>(first + k);
    Channel<Attrib1i> rays(ids);
    RunStats stats = sh::run(program_, {rays}, {}, choice);
    r.backend = stats.backend;
    r.compile_ms += stats.compile_ms;
    r.run_ms += stats.run_ms;
    add_details(r.details, stats.details);
  }
  if (report) *report = r;
  return energy_.values();
}

// A lattice point is shared by the triangles that meet there with the same
// shading normal (a smooth mesh), not across a crease: its luminance is the
// mean over the elements around it, on its side of the surface.
ElementLight luminance_of(const Scene& scene, int k, std::vector<float> energy) {
  const Mesh& m = scene.mesh;
  std::size_t triangles = m.triangles();
  ElementLight out;
  out.subdivision = k;
  out.energy = std::move(energy);
  out.luminance.assign(out.energy.size(), 0.0f);
  out.vertex.assign(side_slot(triangles, 0, lattice_slots(k)) * 3, 0.0f);
  Box bounds = accelerator_bounds(scene);
  float cell = std::max(length(bounds.hi - bounds.lo), 1e-30f) * 1e-5f;
  using Key = std::tuple<long long, long long, long long, int, int, int>;
  auto key_of = [&](Vec3 p, Vec3 n) {
    auto q = [](float x, float step) { return static_cast<long long>(std::llround(x / step)); };
    return Key{q(p.x, cell), q(p.y, cell), q(p.z, cell), static_cast<int>(q(n.x, 0.05f)), static_cast<int>(q(n.y, 0.05f)),
               static_cast<int>(q(n.z, 0.05f))};
  };
  struct Mean {
    Vec3 sum;
    int count = 0;
  };
  std::map<Key, Mean> around;
  std::vector<Key> lattice_key(side_slot(triangles, 0, lattice_slots(k)));
  for (std::size_t t = 0; t < triangles; ++t) {
    Vec3 v0 = m.positions[3 * t], e1 = m.positions[3 * t + 1] - v0, e2 = m.positions[3 * t + 2] - v0;
    Vec3 face = cross(e1, e2);
    float area = 0.5f * length(face) / static_cast<float>(k * k);
    for (int side = 0; side < kSides; ++side) {
      // The side's points meet those of the sides that face the same way
      // with the same shading normal, whichever way their triangles wind.
      Vec3 facing = side == 0 ? face : -1.0f * face;
      std::size_t lattice = side_slot(t, side, lattice_slots(k)), elements = side_slot(t, side, element_slots(k));
      for (int j = 0; j <= k; ++j)
        for (int i = 0; i + j <= k; ++i) {
          float u = static_cast<float>(i) / k, v = static_cast<float>(j) / k;
          Vec3 n = normalize((1 - u - v) * m.normals[3 * t] + u * m.normals[3 * t + 1] + v * m.normals[3 * t + 2]);
          lattice_key[lattice + j * (k + 1) + i] = key_of(v0 + u * e1 + v * e2, dot(n, facing) < 0 ? -1.0f * n : n);
        }
      for_each_element(k, [&](int i, int j, int down) {
        std::size_t slot = elements + 2 * (j * k + i) + down;
        Vec3 e{out.energy[3 * slot], out.energy[3 * slot + 1], out.energy[3 * slot + 2]};
        Vec3 lum = area > 0 ? e * (1 / area) : Vec3{};
        out.luminance[3 * slot] = lum.x, out.luminance[3 * slot + 1] = lum.y, out.luminance[3 * slot + 2] = lum.z;
        int here = j * (k + 1) + i;
        int corners[3] = {down ? here + k + 2 : here, down ? here + k + 1 : here + 1, down ? here + 1 : here + k + 1};
        for (int c : corners) {
          Mean& mean = around[lattice_key[lattice + c]];
          mean.sum = mean.sum + lum;
          ++mean.count;
        }
      });
    }
  }
  for (std::size_t l = 0; l < lattice_key.size(); ++l) {
    auto it = around.find(lattice_key[l]);
    if (it == around.end()) continue;  // a lattice slot past the triangle's diagonal
    Vec3 mean = it->second.sum * (1.0f / static_cast<float>(it->second.count));
    out.vertex[3 * l] = mean.x, out.vertex[3 * l + 1] = mean.y, out.vertex[3 * l + 2] = mean.z;
  }
  return out;
}

}  // namespace sh::rt
