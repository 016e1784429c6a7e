#pragma once
// The lazy octree as a Refiner (sh/waves.hpp): it builds the nodes rays
// ask for, and shows the kernels the octree's tables as built so far.  On
// mpi each rank gets one started from the seed (the triangles and an
// unbuilt root), so each rank builds only what its own chunks need; the
// mpi backend runs waves on a static schedule, so a rank's chunks, and
// the tree it built for them, are the same from render to render.
#include <memory>
#include <string>

#include <sh/waves.hpp>

#include "sh/raytracer/octree.hpp"

namespace sh::rt {

inline constexpr const char* kOctreeRefinerKind = "sh.rt.octree";

// What one process's lazy octree holds (RunStats::refined, per rank).
struct OctreeSummary {
  std::size_t nodes = 0, bytes = 0, pending_bytes = 0;
  std::vector<std::uint64_t> built;  // keys of the nodes it built
  static OctreeSummary read(const std::string& bytes);  // throws sh::Error on a malformed summary
};

class OctreeRefiner : public Refiner {
 public:
  // Stands for the two tables (by id) that OctreeTables made from `tree`.
  OctreeRefiner(std::shared_ptr<Octree> tree, std::uint64_t nodes_table, std::uint64_t triangles_table);
  static std::unique_ptr<Refiner> from_seed(const std::string& seed);

  std::string kind() const override { return kOctreeRefinerKind; }
  std::string seed() const override;
  void bind(std::vector<TableView>& tables) const override;
  // Requests are (node, cell x, y, z): see Octree::build_towards.
  std::size_t refine(const std::vector<std::int32_t>& requests, int width) override;
  std::string summary() const override;

 private:
  std::shared_ptr<Octree> tree_;
  std::uint64_t stands_for_[2];
  std::uint64_t own_id_[2] = {refined_table_id(), refined_table_id()};
  std::uint64_t version_ = 1;
};

}  // namespace sh::rt
