#pragma once
// Sh-era spellings, so that code written for Sh (the seed ray tracer's
// tracer and intersector among it) compiles with cosmetic edits only.
#include "sh/dsl.hpp"

#define SH_COMPAT_TYPE(Name)                 \
  using Sh##Name = sh::Name;                 \
  using ShConst##Name = sh::Const##Name;     \
  using ShInput##Name = sh::Input<sh::Name>; \
  using ShOutput##Name = sh::Output<sh::Name>; \
  using ShInOut##Name = sh::InOut<sh::Name>;
#define SH_COMPAT_FAMILY(Name) \
  SH_COMPAT_TYPE(Name##1f)     \
  SH_COMPAT_TYPE(Name##2f)     \
  SH_COMPAT_TYPE(Name##3f)     \
  SH_COMPAT_TYPE(Name##4f)     \
  SH_COMPAT_TYPE(Name##1i)     \
  SH_COMPAT_TYPE(Name##2i)     \
  SH_COMPAT_TYPE(Name##3i)     \
  SH_COMPAT_TYPE(Name##4i)

SH_COMPAT_FAMILY(Attrib)
SH_COMPAT_FAMILY(Point)
SH_COMPAT_FAMILY(Vector)
SH_COMPAT_FAMILY(Normal)
SH_COMPAT_FAMILY(Color)
SH_COMPAT_FAMILY(TexCoord)
SH_COMPAT_FAMILY(Position)
#undef SH_COMPAT_FAMILY
#undef SH_COMPAT_TYPE

using ShProgram = sh::Program;
using ShStream = sh::Stream;
template <class T> using ShChannel = sh::Channel<T>;
template <class T> using ShArray1D = sh::Table1D<T>;
template <class T> using ShArray2D = sh::Table2D<T>;
template <class T> using ShArray3D = sh::Table3D<T>;
template <class T> using ShTable1D = sh::Table1D<T>;
template <class T> using ShTable2D = sh::Table2D<T>;
template <class T> using ShTable3D = sh::Table3D<T>;
using ShMatrix3x3f = sh::Matrix3x3f;
using ShMatrix4x4f = sh::Matrix4x4f;
using ShMatrix3x4f = sh::Matrix3x4f;

inline void shUseBackend(const std::string& name) { sh::use_backend(name); }

namespace sh::detail {
// A number given to SH_DECL's variable: the variable's type is known only
// where the number initialises it.
template <Number N>
struct NamedNumber {
  const char* name;
  N number;
  template <AttribLike A>
  operator A() const {
    A named(number);
    named.name(name);
    return named;
  }
};

struct Named {
  const char* name;
  template <AttribLike A>
  Plain<A> operator=(const A& value) const {
    Plain<A> named = value;
    named.name(name);
    return named;
  }
  template <Number N>
  NamedNumber<N> operator=(N number) const {
    return {name, number};
  }
  // No initial value: a variable of the declared type, named.
  template <AttribLike A>
  operator A() const {
    A named;
    named.name(name);
    return named;
  }
};
}  // namespace sh::detail

// Sh's SH_DECL(name): declares a variable and gives it its own name in the
// IR, in each of Sh's forms:
//   ShAttrib1f SH_DECL(hit) = disc >= 0.0f;   ShAttrib1f SH_DECL(t) = 1.0f;   ShPoint3f SH_DECL(p);
#define SH_DECL(var) var = ::sh::detail::Named{#var}
#define SH_NAMED(var) var.name(#var)

// Host memory, Sh's way of handing a program the user's data (sh/memory.hpp):
//   ShHostMemoryPtr mem = new ShHostMemory(n * 3 * sizeof(float), data, SH_FLOAT);
//   ShChannel<ShPoint3f> points(mem, n);      // no copy: the channel is data
//   result = program << points;               // result on memory too
// When the user's memory holds the results: when the assignment (or
// sh::run) that runs the program returns, on every backend.  interp and cpu
// write the memory in place; opencl writes it in place on a device that
// shares host memory (PoCL on the CPU) and otherwise copies into it before
// returning; mpi gathers every rank's share into rank 0's memory before
// returning (the other ranks serve rank 0 and never return to the caller).
// Input channels are read during the run only.  A table on memory
// (texture.memory(mem)) is read in place by interp and cpu, and copied by
// opencl and mpi, which keep the copy until the memory's dirty() (or
// texture.memory(mem) again): after writing the memory, call dirty().
// Only SH_FLOAT, SH_DOUBLE and SH_INT memory exists: values are never
// converted between a memory's type and a channel's.  docs/sh-compat.md.
using ShMemory = sh::HostMemory;
using ShHostMemory = sh::HostMemory;
using ShHostStorage = sh::HostMemory;
using ShMemoryPtr = sh::MemoryPtr;
using ShHostMemoryPtr = sh::MemoryPtr;
using ShHostStoragePtr = sh::MemoryPtr;
using ShValueType = sh::ir::Scalar;
inline constexpr ShValueType SH_FLOAT = sh::ir::Scalar::F32;
inline constexpr ShValueType SH_DOUBLE = sh::ir::Scalar::F64;
inline constexpr ShValueType SH_INT = sh::ir::Scalar::I32;

// Sh's shref_dynamic_cast<ShHostStorage>(memory->findStorage("host")): host
// memory is the only storage here, so the cast is the memory itself.
template <class T>
sh::MemoryPtr shref_dynamic_cast(const sh::MemoryPtr& memory) {
  static_assert(std::is_same_v<T, sh::HostMemory>, "only host storage exists: shref_dynamic_cast<ShHostStorage>");
  return memory;
}
