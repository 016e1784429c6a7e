#pragma once
// Everything a user needs: the language and the backend interface.  The
// backends are not named here: each registers itself when its library is
// linked (sh::sh links every one built), and sh::backends() lists them.
// Include a backend's own header (sh/cpu.hpp, sh/opencl.hpp, sh/mpi.hpp)
// only for its own API: typed options, statistics, devices, MPI ranks.
#include "sh/compare.hpp"
#include "sh/dsl.hpp"
