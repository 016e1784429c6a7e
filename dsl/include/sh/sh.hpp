#pragma once
// Everything a user needs: the language and every backend that was built.
// A backend's header registers it when included (only the targets linked
// through sh::sh put those headers on the include path).
#include "sh/dsl.hpp"

#if __has_include(<sh/cpu.hpp>)
#include <sh/cpu.hpp>
#endif
#if __has_include(<sh/opencl.hpp>)
#include <sh/opencl.hpp>
#endif
#if __has_include(<sh/mpi.hpp>)
#include <sh/mpi.hpp>
#endif
