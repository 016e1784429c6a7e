// Ordinary C++ functions called while recording are inlined into the
// kernel: this is how the seed's intersector is a C++ method.  Plain C++
// `if` and `for` run at recording time, so they specialise the kernel.
#include <cstdio>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

// Ray-sphere intersection: the distance to the nearest hit, or -1.
Attrib1f hit_sphere(const Point3f& origin, const Vector3f& dir, const Point3f& centre, float radius) {
  Vector3f oc = origin - centre;
  Attrib1f b = dot(oc, dir);
  Attrib1f c = dot(oc, oc) - radius * radius;
  Attrib1f disc = b * b - c;
  Attrib1f t = -b - sqrt(max(disc, 0.0f));
  return cond(disc >= 0.0f && t > 0.0f, t, ConstAttrib1f(-1.0f));
}

Program make_tracer(const std::vector<float>& radii) {
  return SH_BEGIN_PROGRAM("spheres") {
    InputPoint3f origin;
    InputVector3f dir;
    OutputAttrib1f nearest;
    nearest = 1e30f;
    // A C++ loop: one intersection test per sphere, unrolled while recording.
    for (std::size_t i = 0; i < radii.size(); ++i) {
      Attrib1f t = hit_sphere(origin, normalize(dir), ConstPoint3f(3.0f * i, 0, 5), radii[i]);
      nearest = cond(t > 0.0f, min(nearest, t), nearest);
    }
  } SH_END;
}

int main() {
  Program tracer = make_tracer({1.0f, 0.5f});
  std::printf("%s\nafter the passes:\n%s\n", print(tracer).c_str(), print_optimized(tracer).c_str());
  Channel<Point3f> origin(std::vector<float>{0, 0, 0, 3, 0, 0});
  Channel<Vector3f> dir(std::vector<float>{0, 0, 1, 0, 0, 1});
  Channel<Attrib1f> nearest;
  run(tracer, {origin, dir}, {nearest});
  std::printf("nearest hits: %g %g\n", nearest[0], nearest[1]);
  return 0;
}
