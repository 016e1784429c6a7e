// Uses of the language that must not compile.  CTest compiles this file
// once per case (-DSH_MISUSE_<case>, tests/CMakeLists.txt) and passes where
// the compiler prints the library's own message naming the operation; with
// no case defined, every line is the valid form and the file compiles.
#include <sh/dsl.hpp>

using namespace sh;

void misuse(Attrib1f f, Attrib1i i, Attrib3f v, Attrib2f w, Matrix4x4f m) {
#if defined(SH_MISUSE_mad)
  (void)mad(f, i, f);
#elif defined(SH_MISUSE_mod)
  (void)(f % i);
#elif defined(SH_MISUSE_mod_assign)
  i %= f;
#elif defined(SH_MISUSE_widths)
  (void)(v + w);
#elif defined(SH_MISUSE_assign)
  v = w;
#elif defined(SH_MISUSE_clamp)
  (void)clamp(f, i, 1);
#elif defined(SH_MISUSE_lerp)
  (void)lerp(i, v, v);
#elif defined(SH_MISUSE_cond)
  (void)cond(f, f, i);
#elif defined(SH_MISUSE_min)
  (void)min(f, i);
#elif defined(SH_MISUSE_matrix)
  (void)(m | w);
#else
  (void)mad(f, f.cast<float>(), 1.0f);
  (void)(f % i.cast<float>());
  i %= f.cast<std::int32_t>();
  (void)(v + w(0));
  f = i;  // converts, as in Sh
  v = w(0);
  (void)clamp(f, 0, 1);
  (void)lerp(f, v, v);
  (void)cond(i, f, 2.0f);
  (void)min(f, i.cast<float>());
  (void)(m | v);
#endif
}
