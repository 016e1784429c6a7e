#pragma once
// Tables: read-only arrays of 1, 2 or 3 dimensions (Sh's arrays and
// textures) filled on the host and read by kernels.  t[i] reads element i
// with integer coordinates; t(x) with coordinates in [0, 1] (nearest
// element).  Outside the table both clamp to the edge, or wrap around, or
// give zero, as the table's edge() says.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "sh/attrib.hpp"
#include "sh/detail/buffer.hpp"
#include "sh/error.hpp"

namespace sh {

using Edge = ir::Edge;

template <int Rank, class E>
class Table {
  static_assert(Rank >= 1 && Rank <= 3, "tables have 1, 2 or 3 dimensions");

 public:
  using element_type = E;
  using scalar = typename E::scalar_type;
  static constexpr int components = E::width;

  template <std::convertible_to<int>... D>
    requires(sizeof...(D) == Rank)
  explicit Table(D... dims) : storage_(std::make_shared<detail::TableStorage>()) {
    storage_->decl = ir::TableDecl{E::ir_type(), Rank, ""};
    int d[] = {static_cast<int>(dims)...};
    std::size_t count = 1;
    for (int i = 0; i < Rank; ++i) {
      if (d[i] < 1) throw Error("a table dimension must be at least 1, got " + std::to_string(d[i]));
      storage_->dims[i] = d[i];
      count *= static_cast<std::size_t>(d[i]);
    }
    storage_->buffer = detail::Buffer(E::ir_type(), count);
  }

  std::size_t size() const { return storage_->buffer.size(); }
  const std::array<int, 3>& dims() const { return storage_->dims; }
  Table& name(const std::string& n) {
    storage_->decl.name = n;
    return *this;
  }
  // What a read outside the table gives: the nearest element on the edge
  // (Edge::Clamp, the default), the element the coordinates wrap around to
  // (Edge::Repeat), or zero (Edge::Zero).  Programs recorded from now on
  // read it so.
  Table& edge(Edge e) {
    storage_->decl.edge = e;
    return *this;
  }

  // Copies size() * components scalars in (elements in x-fastest order).
  void assign(const std::vector<scalar>& data) {
    if (data.size() != size() * components)
      throw Error("table '" + storage_->decl.name + "' holds " + std::to_string(size() * components) +
                  " scalars; " + std::to_string(data.size()) + " were given");
    for (std::size_t i = 0; i < size(); ++i)
      for (int c = 0; c < components; ++c) storage_->buffer.set(i, c, static_cast<double>(data[i * components + c]));
    touch();
  }
  void set(std::size_t element, const std::array<scalar, E::width>& value) {
    if (element >= size()) throw Error("table element " + std::to_string(element) + " is out of range");
    for (int c = 0; c < components; ++c) storage_->buffer.set(element, c, static_cast<double>(value[c]));
    touch();
  }

  template <class I>
  E operator[](const I& coords) const {
    return read(ir::Op::Fetch, coords);
  }
  template <class I>
  E operator()(const I& coords) const {
    return read(ir::Op::Sample, coords);
  }
  // Asks for element `coords` (integer coordinates) to be brought near the
  // processor ahead of a read of it that would otherwise wait on memory: a
  // tree walk's children, say, prefetched when their parent is read.
  // Changes no result, at any coordinates; one outside the table asks for
  // nothing in it, and far outside may cost the processor a page walk.  A
  // backend may ignore it.
  template <class I>
  void prefetch(const I& coords) const {
    if constexpr (Number<I>)
      detail::table_prefetch(storage_, detail::constant(ir::Scalar::I32, static_cast<double>(coords)));
    else
      detail::table_prefetch(storage_, coords.value());
  }

  // From now on the table's elements are the first size() elements of
  // `memory` (Sh's texture.memory(m)), read in place where the backend can.
  // After writing the memory, call memory->dirty() (or this again): a
  // backend that keeps a copy of the table (opencl, mpi) sends it again only then.
  void memory(MemoryPtr memory) {
    storage_->buffer.view(std::move(memory), size(), describe());
    storage_->touch();
  }
  // The memory the elements lie in (for a table that allocated its own,
  // that storage, handed out without a copy: write it, then dirty()).
  MemoryPtr memory() const { return storage_->buffer.memory(); }

  const std::shared_ptr<detail::TableStorage>& storage() const { return storage_; }

 private:
  void touch() { storage_->touch(); }
  std::string describe() const {
    std::string d = "table" + (storage_->decl.name.empty() ? "" : " '" + storage_->decl.name + "'") + " of " +
                    ir::type_name(E::ir_type()) + " (" + std::to_string(dims()[0]);
    for (int i = 1; i < Rank; ++i) d += " x " + std::to_string(dims()[i]);
    return d + ")";
  }

  template <class I>
  E read(ir::Op op, const I& coords) const {
    detail::Value c;
    if constexpr (Number<I>)
      c = detail::constant(std::is_floating_point_v<I> ? ir::Scalar::F32 : ir::Scalar::I32, static_cast<double>(coords));
    else
      c = coords.value();
    return E(detail::FromValue{}, detail::table_read(storage_, op, c));
  }

  std::shared_ptr<detail::TableStorage> storage_;
};

template <class E> using Table1D = Table<1, E>;
template <class E> using Table2D = Table<2, E>;
template <class E> using Table3D = Table<3, E>;

}  // namespace sh
