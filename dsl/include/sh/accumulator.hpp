#pragma once
// Accumulators: the language's reduction.  A kernel adds into an
// accumulator's elements (a scatter-add: `energy.add(index, value)`), any
// number of times per stream element and from any element; the host reads
// the sums after the run.  Every run adds to what the accumulator holds, so
// the host clears it when it wants fresh sums.  The order of the additions
// is the backend's (threads, lanes, work items, ranks), so float sums agree
// across backends to rounding, not bit for bit; int sums agree exactly.
#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "sh/attrib.hpp"
#include "sh/detail/buffer.hpp"
#include "sh/error.hpp"

namespace sh {

namespace detail {
void scatter_add(const std::shared_ptr<TableStorage>& accumulator, const Value& index, const Value& value);
}

template <class E>
class Accumulator {
  static_assert(std::is_same_v<typename E::scalar_type, float> || std::is_same_v<typename E::scalar_type, int>,
                "accumulators hold float or int elements");

 public:
  using scalar = typename E::scalar_type;
  static constexpr int components = E::width;

  explicit Accumulator(int count, std::string name = "") : storage_(std::make_shared<detail::TableStorage>()) {
    if (count < 1) throw Error("an accumulator holds at least 1 element, got " + std::to_string(count));
    storage_->decl = ir::TableDecl{E::ir_type(), 1, std::move(name), true};
    storage_->dims[0] = count;
    storage_->buffer = detail::Buffer(E::ir_type(), static_cast<std::size_t>(count));
    storage_->filled = true;
  }

  std::size_t size() const { return storage_->buffer.size(); }
  const std::string& name() const { return storage_->decl.name; }

  // Inside a program: adds `value` to element `index` (clamped to the edge,
  // as table reads are).
  template <class I, class V>
  void add(const I& index, const V& value) const {
    detail::scatter_add(storage_, detail::value_or_constant(index, ir::Scalar::I32),
                        detail::value_or_constant(value, E::ir_type().scalar));
  }

  // On the host: the sums, element by element, components contiguous.
  std::vector<scalar> values() const {
    std::vector<scalar> out(size() * components);
    for (std::size_t i = 0; i < size(); ++i)
      for (int c = 0; c < components; ++c) out[i * components + c] = static_cast<scalar>(storage_->buffer.get(i, c));
    return out;
  }
  // Zero sums, in its own storage or in memory it was moved into.
  void clear() {
    std::memset(storage_->buffer.data(), 0, storage_->buffer.bytes());
    storage_->buffer.written();
    ++storage_->version;
  }

  const std::shared_ptr<detail::TableStorage>& storage() const { return storage_; }

 private:
  std::shared_ptr<detail::TableStorage> storage_;
};

}  // namespace sh
