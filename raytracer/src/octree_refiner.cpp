#include "sh/raytracer/octree_refiner.hpp"

#include <cstring>

#include "sh/error.hpp"

namespace sh::rt {
namespace {

// Every process that might serve an mpi render can make one.
const bool registered = [] {
  register_refiner(kOctreeRefinerKind, OctreeRefiner::from_seed);
  return true;
}();

class Writer {
 public:
  template <class T>
  Writer& put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  template <class T>
  Writer& array(const std::vector<T>& v) {
    put(static_cast<std::uint64_t>(v.size()));
    bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    return *this;
  }
  std::string bytes;
};

class Reader {
 public:
  Reader(const std::string& bytes, const char* what) : bytes_(bytes), what_(what) {}
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  template <class T>
  std::vector<T> array() {
    auto n = get<std::uint64_t>();
    if (n > bytes_.size() / sizeof(T)) fail();
    std::vector<T> v(n);
    std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }

 private:
  const char* take(std::size_t n) {
    if (n > bytes_.size() - at_) fail();
    at_ += n;
    return bytes_.data() + at_ - n;
  }
  [[noreturn]] void fail() const { throw Error(std::string("malformed octree ") + what_ + " (" + std::to_string(bytes_.size()) + " bytes)"); }
  const std::string& bytes_;
  const char* what_;
  std::size_t at_ = 0;
};

}  // namespace

OctreeSummary OctreeSummary::read(const std::string& bytes) {
  Reader r(bytes, "summary");
  OctreeSummary s;
  s.nodes = r.get<std::uint64_t>();
  s.bytes = r.get<std::uint64_t>();
  s.pending_bytes = r.get<std::uint64_t>();
  s.built = r.array<std::uint64_t>();
  return s;
}

OctreeRefiner::OctreeRefiner(std::shared_ptr<Octree> tree, std::uint64_t nodes_table, std::uint64_t triangles_table)
    : tree_(std::move(tree)), stands_for_{nodes_table, triangles_table} {
  (void)registered;
}

std::string OctreeRefiner::seed() const {
  Writer w;
  w.put(tree_->limits()).put(tree_->bounds()).put(stands_for_[0]).put(stands_for_[1]).array(tree_->positions());
  return w.bytes;
}

std::unique_ptr<Refiner> OctreeRefiner::from_seed(const std::string& seed) {
  Reader r(seed, "seed");
  auto limits = r.get<OctreeLimits>();
  auto bounds = r.get<Box>();
  auto nodes = r.get<std::uint64_t>(), triangles = r.get<std::uint64_t>();
  auto tree = std::make_shared<Octree>(r.array<Vec3>(), bounds, limits);
  return std::make_unique<OctreeRefiner>(std::move(tree), nodes, triangles);
}

void OctreeRefiner::bind(std::vector<TableView>& tables) const {
  const std::vector<std::int32_t>* data[2] = {&tree_->nodes(), &tree_->triangles()};
  for (TableView& t : tables)
    for (int k = 0; k < 2; ++k)
      if (t.id == stands_for_[k] || t.id == own_id_[k]) {
        t.data = data[k]->data();
        t.source = nullptr;  // this process's own tree, whole, even where the run split the tables
        t.dims = {static_cast<int>(data[k]->size()), 1, 1};
        t.id = own_id_[k];
        t.version = version_;
      }
}

std::size_t OctreeRefiner::refine(const std::vector<std::int32_t>& requests, int width) {
  if (width != 4) throw Error("octree refiner: requests are (node, cell x, y, z), not " + std::to_string(width) + " ints");
  std::size_t built = tree_->build_towards(requests);
  version_ += built > 0;
  return built;
}

std::string OctreeRefiner::summary() const {
  Writer w;
  w.put(static_cast<std::uint64_t>(tree_->nodes().size()))
      .put(static_cast<std::uint64_t>(tree_->bytes()))
      .put(static_cast<std::uint64_t>(tree_->pending_bytes()))
      .array(tree_->built_keys());
  return w.bytes;
}

}  // namespace sh::rt
