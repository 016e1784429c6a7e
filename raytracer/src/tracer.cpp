// Ray generation and the tracer, after the seed: primary rays from a
// pinhole camera; at each hit, shadow rays to every light (a recorded loop
// over the lights table) and to sample points of every disk light, Phong
// shading with barycentric normals and colours, and a recorded loop of
// reflections to a set depth.
#include "sh/raytracer/kernels.hpp"
#include "sh/error.hpp"
#include "elements.hpp"
#include "sh/raytracer/bidirectional.hpp"
#include "shading.hpp"

namespace sh::rt {
namespace {

// With `diffuse` false only the highlight: the light pass brings the rest.
Color3f phong(const Surface& x, const Vector3f& view, const Vector3f& dir, const Attrib1f& facing, bool diffuse = true) {
  Attrib1f highlight = x.specular * pow(max(dot(mirror(dir, x.n), view), 0.0f), x.shininess);
  if (!diffuse) return fillcast<3>(highlight);
  return x.diffuse * facing + highlight;
}

// The light pass's luminance at a hit: its element's lattice points on the
// side the ray met, interpolated.
Color3f vertex_light(const SceneTables& s, const Surface& x, const Vector3f& d, const Attrib1i& tri, const Attrib2f& uv) {
  const LuminanceTables& l = *s.luminance;
  ElementAt e = element_at(uv, l.subdivision);
  Attrib1i base = (kSides * tri + side_met(x.ng, d)) * lattice_slots(l.k);
  return e.weights(0) * l.vertex[base + e.corners(0)] + e.weights(1) * l.vertex[base + e.corners(1)] +
         e.weights(2) * l.vertex[base + e.corners(2)];
}

// Direct light from every point light the point sees: Phong, shadowed.
Color3f direct(const SceneTables& s, Intersector& intersect, const Surface& x, const Vector3f& view, bool diffuse) {
  Color3f sum = ConstColor3f(0.0f, 0.0f, 0.0f);
  SH_FOR(Attrib1i l = 0, l < s.light_count, l += 1) {
    Attrib3f light_pos = s.lights[2 * l], light_color = s.lights[2 * l + 1];
    Vector3f to_light = light_pos - x.p;
    Attrib1f dist = length(to_light);
    Vector3f dir = to_light / dist;
    Attrib1f facing = dot(x.n, dir);
    SH_IF(facing > 0.0f) {
      Attrib1f shadowed = intersect.occluded(leave(x, dir), dir, dist);
      sum += (1.0f - shadowed) * phong(x, view, dir, facing, diffuse) * light_color;
    } SH_ENDIF;
  } SH_ENDFOR;
  return sum;
}

// Shadow rays to a disk light's samples stop this share short of them: a
// disk set into a surface (a ceiling's light) lies in that surface's
// plane, where the surface would stop every ray at the light itself.  A
// point light's rays go all the way: an occluder near it still shadows.
constexpr float kShortOfLight = 1.0f - 1e-4f;

// Light from every disk light: Phong towards its centre, times the share
// of shadow rays to its sample points that reach it (a sample behind the
// surface's tangent plane does not).  The samples are turned by a
// per-pixel angle so the pattern does not repeat in the penumbra.
Color3f soft_direct(const SceneTables& s, Intersector& intersect, const Surface& x, const Vector3f& view,
                    const Attrib2f& turn) {
  Color3f sum = ConstColor3f(0.0f, 0.0f, 0.0f);
  SH_FOR(Attrib1i l = 0, l < s.disk_count, l += 1) {
    Attrib3f centre = s.disks[4 * l], du = s.disks[4 * l + 1], dv = s.disks[4 * l + 2], color = s.disks[4 * l + 3];
    Vector3f to_centre = centre - x.p;
    Vector3f dir = to_centre / length(to_centre);
    Attrib1f facing = dot(x.n, dir);
    SH_IF(facing > 0.0f) {
      Attrib1f reached = 0.0f;
      SH_FOR(Attrib1i k = 0, k < s.sample_count, k += 1) {
        Attrib2f xy = s.samples[k];
        Attrib1f a = xy(0) * turn(0) - xy(1) * turn(1), b = xy(0) * turn(1) + xy(1) * turn(0);
        Vector3f to_sample = centre + a * du + b * dv - x.p;
        Attrib1f dist = length(to_sample);
        Vector3f towards = to_sample / dist;
        SH_IF(dot(x.n, towards) > 0.0f) {
          reached += 1.0f - intersect.occluded(leave(x, towards), towards, dist * kShortOfLight);
        } SH_ENDIF;
      } SH_ENDFOR;
      sum += reached / s.sample_count.cast<float>() * phong(x, view, dir, facing) * color;
    } SH_ENDIF;
  } SH_ENDFOR;
  return sum;
}

// cos and sin of a pseudo-random angle per pixel, from integer hashing of
// the pixel (the same on every backend).
Attrib2f pixel_turn(const Attrib2f& pixel) {
  Attrib2i p = floor(pixel).cast<std::int32_t>();
  Attrib1i h = p(0) * 1103515245 + p(1) * 12345 + 7;
  // |h| mod 4096 is |C's h % 4096| (the angles the images were made with);
  // abs(INT_MIN) wraps to INT_MIN, whose remainder is 0 either way.
  Attrib1f angle = (abs(h) % 4096).cast<float>() * (6.2831853f / 4096.0f);
  return join(cos(angle), sin(angle));
}

// Where a pixel's path is as a bounce starts, and how far the bounce's ray
// has walked: all a stopped pixel needs to resume.
struct Path {
  static Path start(const Point3f& origin, const Vector3f& direction);
  Point3f o;
  Vector3f d;
  Attrib1f bounce;  // bounces done
  Color3f color, weight;
  Attrib1f distance;  // of the primary hit, -1 where none
  Attrib1i triangle;  // of the primary hit, -1 where none
  WalkState walk;
};

Path Path::start(const Point3f& origin, const Vector3f& direction) {
  return {origin, direction, ConstAttrib1f(0.0f), ConstColor3f(0.0f, 0.0f, 0.0f), ConstColor3f(1.0f, 1.0f, 1.0f),
          ConstAttrib1f(-1.0f), ConstAttrib1i(-1), WalkState::fresh()};
}

// The path as the lazy tracer's inputs and outputs, in PathChannels' order.
struct PathInputs {
  InputAttrib4f origin_bounce, direction_distance, color_best, weight_u, cell_v;
  InputAttrib1i triangle, walk_triangle;
  Path path() const {
    return {origin_bounce(0, 1, 2), direction_distance(0, 1, 2), origin_bounce(3), color_best(0, 1, 2),
            weight_u(0, 1, 2), direction_distance(3), triangle,
            WalkState{cell_v(0, 1, 2), color_best(3), walk_triangle, join(weight_u(3), cell_v(3))}};
  }
};

void write_path(const Path& p) {
  OutputAttrib4f origin_bounce, direction_distance, color_best, weight_u, cell_v;
  OutputAttrib1i triangle, walk_triangle;
  origin_bounce = join(p.o, p.bounce);
  direction_distance = join(p.d, p.distance);
  color_best = join(p.color, p.walk.best);
  weight_u = join(p.weight, p.walk.uv(0));
  cell_v = join(p.walk.cell, p.walk.uv(1));
  triangle = p.triangle;
  walk_triangle = p.walk.triangle;
}

// Follows the path to its end: shade each hit, or add the background and
// stop.  Over a lazy octree the path stops where a ray meets an unbuilt
// node, as it was when that bounce began (its ray's walk kept).  With
// `one_bounce` (a wavefront) it takes one bounce and returns 1 where the
// path has more to go.
Attrib1f trace(const SceneTables& s, const Features& f, Intersector& intersect, const Attrib2f& turn, Path& p,
               bool one_bounce) {
  // Returns 1 where the path ends with this bounce (however many are left).
  auto bounce = [&](bool in_loop) -> Attrib1f {
    Attrib1f hit = intersect.resume(p.o, p.d, p.walk);
    // A stopped walk's nearest triangle so far is not a hit yet: no shading.
    if (intersect.may_stop()) hit = hit && !intersect.stopped();
    Color3f add = p.weight * s.background, weight = ConstColor3f(0.0f, 0.0f, 0.0f);
    Point3f o = p.o;
    Vector3f d = p.d;
    SH_IF(hit) {
      Surface x = surface_at(s, p.d, p.walk.triangle, p.walk.uv, f);
      Color3f local = s.ambient * x.diffuse;
      if (f.luminance) local += x.diffuse * vertex_light(s, x, p.d, p.walk.triangle, p.walk.uv);
      if (f.shadows) local += direct(s, intersect, x, -p.d, !f.luminance);
      if (f.soft_shadows) local += soft_direct(s, intersect, x, -p.d, turn);
      if (f.reflections || f.refractions) {
        Continuation next = go_on(x, p.d, f);
        Attrib1f shaded = f.refractions ? x.shaded() : 1.0f - x.reflectivity;
        add = p.weight * shaded * local;
        weight = p.weight * next.share;
        d = next.d;
        o = next.o;
      } else {
        add = p.weight * local;
      }
    } SH_ENDIF;
    auto advance = [&] {
      Attrib1f first = p.bounce == 0.0f && hit;
      p.distance = cond(first, p.walk.best, p.distance);
      p.triangle = cond(first, p.walk.triangle, p.triangle);
      p.color += add;
      p.weight = weight;
      p.o = o;
      p.d = d;
      p.bounce += 1.0f;
      p.walk = WalkState::fresh();
    };
    if (intersect.may_stop()) {
      SH_IF(!intersect.stopped()) { advance(); } SH_ENDIF;
      if (in_loop) SH_BREAK(intersect.stopped());  // by a shadow ray
    } else {
      advance();
    }
    Attrib1f ends = !hit || max_component(p.weight) <= 0.0f;
    if (in_loop) SH_BREAK(ends);
    return ends;
  };
  if (!f.reflections && !f.refractions) {
    bounce(false);
    return 0.0f;
  }
  if (one_bounce) return !bounce(false) && p.bounce <= s.max_bounces;
  SH_WHILE(p.bounce <= s.max_bounces) { bounce(true); } SH_ENDWHILE;
  return 0.0f;
}

}  // namespace

Program raygen_program(const SceneTables& s) {
  return SH_BEGIN_PROGRAM("raygen") {
    InputAttrib2f pixel;  // the pixel's centre, (x + 0.5, y + 0.5), row 0 at the top
    OutputPoint3f origin;
    OutputVector3f direction;
    OutputAttrib2f pixel_out;  // passed on: soft shadows turn their samples by it
    Attrib1f aspect = s.image_size(0) / s.image_size(1);
    Attrib2f ndc = 2.0f * pixel / s.image_size - 1.0f;
    Attrib1f x = ndc(0) * s.tan_half_fov * aspect, y = -ndc(1) * s.tan_half_fov;
    origin = s.eye;
    direction = normalize(s.forward + x * s.right + y * s.up);
    pixel_out = pixel;
  } SH_END;
}

Program tracer_program(const SceneTables& s, Features f, bool one_bounce) {
  bool lazy = s.octree && s.octree->lazy;
  if (lazy && one_bounce)
    throw Error("the tracer over a lazy octree runs in waves of its own (a ray stops where the tree is unbuilt), "
                "not one bounce a wave");
  return SH_BEGIN_PROGRAM("tracer") {
    Path p;
    Attrib2f at;
    if (lazy || one_bounce) {
      InputAttrib2f pixel;
      PathInputs in;
      at = pixel;
      p = in.path();
    } else {
      InputPoint3f origin;
      InputVector3f direction;
      InputAttrib2f pixel;
      at = pixel;
      p = Path::start(origin, direction);
    }
    OutputColor3f color;
    OutputAttrib1f distance;
    OutputAttrib1i triangle;
    Intersector intersect(s);
    Attrib1f goes_on = trace(s, f, intersect, f.soft_shadows ? pixel_turn(at) : Attrib2f(1.0f, 0.0f), p, one_bounce);
    color = p.color;
    distance = p.distance;
    triangle = p.triangle;
    if (lazy) {
      OutputAttrib4i request;
      request = intersect.request();
      write_path(p);
    }
    if (one_bounce) {
      OutputAttrib1i request;  // 0: another wave, -1: done
      request = goes_on.cast<std::int32_t>() - 1;
      write_path(p);
    }
  } SH_END;
}

Program path_start_program() {
  return SH_BEGIN_PROGRAM("path_start") {
    InputPoint3f origin;
    InputVector3f direction;
    InputAttrib2f pixel;
    OutputAttrib2f pixel_out;
    pixel_out = pixel;
    write_path(Path::start(origin, direction));
  } SH_END;
}

}  // namespace sh::rt
