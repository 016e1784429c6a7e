#include "coordinator.hpp"
#include "sh/mpi.hpp"
#include "world.hpp"

namespace sh::mpi {
namespace {

class MpiBackend : public Backend {
 public:
  std::string name() const override { return "mpi"; }

  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    // Ranks other than 0 reach here running the same code as rank 0; from
    // now on they serve it instead.
    if (ensure_started() != 0) serve();
    Options with_local = o;
    if (with_local.local_backend.empty()) {
      std::vector<std::string> names = backend_names();
      with_local.local_backend = std::find(names.begin(), names.end(), "cpu") != names.end() ? "cpu" : "interp";
    }
    return coordinator(p, with_local);
  }

  std::vector<std::string> describe() const override {
    return {"mpi: Open MPI ranks (start with mpirun -np N), each running a local backend (cpu by default)"};
  }
};

}  // namespace

void register_backend() {
  sh::register_backend("mpi", [] { return std::make_unique<MpiBackend>(); });
}

}  // namespace sh::mpi
