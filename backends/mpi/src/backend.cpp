#include "coordinator.hpp"
#include "options.hpp"
#include "sh/mpi.hpp"
#include "world.hpp"

namespace sh::mpi {
namespace {

class MpiBackend : public Backend {
 public:
  std::string name() const override { return "mpi"; }

  std::unique_ptr<Kernel> compile(const ir::Program& p, const sh::Options& o) override {
    // Ranks other than 0 reach here running the same code as rank 0; from
    // now on they serve it instead.
    if (ensure_started() != 0) serve();
    check_thread(p.name);
    return coordinator(p, o);
  }

  std::vector<Setting> settings() const override { return mpi::settings(); }
  int lanes(const sh::Options& o) const override {
    return find_backend(local_backend_name(o.get<Options>())).lanes(local_options(o));
  }
  BackendOptions default_options() const override { return Options{}; }

  std::vector<std::string> describe() const override {
    return {"mpi: Open MPI ranks (start with mpirun -np N), each running a local backend (" + preferred_backend_name("mpi") +
            " by default)"};
  }
};

// Registered as the library loads: linking it is enough.
const bool registered = (sh::register_backend("mpi", [] { return std::make_unique<MpiBackend>(); }), true);

}  // namespace
}  // namespace sh::mpi
