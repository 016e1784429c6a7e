#pragma once
// Channels hold host data for one input or output of a program (structure
// of arrays: one channel per input); `a & b` makes a stream of several, and
// a program runs by assignment, as in Sh:  out = p << (a & b);
#include <memory>
#include <vector>

#include "sh/attrib.hpp"
#include "sh/backend.hpp"
#include "sh/detail/buffer.hpp"
#include "sh/error.hpp"

namespace sh {

class Stream;

// A program applied to input streams, run when assigned to outputs.
struct Application {
  Program program;
  std::vector<std::shared_ptr<detail::Buffer>> inputs;
};

template <class A>
class Channel {
 public:
  using scalar = typename A::scalar_type;
  static constexpr int components = A::width;

  explicit Channel(std::size_t count = 0) : buffer_(std::make_shared<detail::Buffer>(A::ir_type(), count)) {}
  // data holds count * components scalars.
  explicit Channel(const std::vector<scalar>& data) : Channel(data.size() / components) {
    if (data.size() % components != 0)
      throw Error("a channel of " + std::to_string(components) + "-component elements cannot hold " +
                  std::to_string(data.size()) + " scalars");
    for (std::size_t i = 0; i < data.size(); ++i) buffer_->set(i / components, static_cast<int>(i % components), static_cast<double>(data[i]));
  }

  // `count` elements in `memory`, read and written in place where the
  // backend can (Sh's ShChannel(memory, count)); the channel shares
  // ownership of the memory.  Throws sh::Error where they do not fit.
  Channel(MemoryPtr memory, std::size_t count) : Channel() { this->memory(std::move(memory), count); }

  std::size_t size() const { return buffer_->size(); }
  // Makes the channel a width x height x depth grid, row-major, of as many
  // elements: a program writing it runs over that launch domain, and
  // position() reads each element's place in it.
  void shape(std::size_t width, std::size_t height = 1, std::size_t depth = 1) { buffer_->shape({width, height, depth}); }
  std::array<std::size_t, 3> shape() const { return buffer_->shape(); }
  std::size_t count() const { return buffer_->size(); }  // Sh's name
  void resize(std::size_t count) { buffer_->resize(count); }
  // The memory the elements lie in (for a channel that allocated its own,
  // that storage, handed out without a copy).
  MemoryPtr memory() const { return buffer_->memory(); }
  // From now on the channel holds `count` elements in `memory`; every
  // stream built from this channel sees the change.
  void memory(MemoryPtr memory, std::size_t count) {
    buffer_->view(std::move(memory), count, "a channel of " + ir::type_name(A::ir_type()));
  }
  // The i-th scalar of the storage; bool channels are stored as int32.
  using stored = std::conditional_t<std::is_same_v<scalar, bool>, std::int32_t, scalar>;
  stored* data() { return static_cast<stored*>(buffer_->data()); }
  const stored* data() const { return static_cast<const stored*>(buffer_->data()); }
  stored& operator[](std::size_t i) { return data()[i]; }
  const stored& operator[](std::size_t i) const { return data()[i]; }
  std::vector<stored> values() const { return std::vector<stored>(data(), data() + size() * components); }

  operator std::shared_ptr<detail::Buffer>() const { return buffer_; }

  Channel& operator=(const Application& app) {
    run(app.program, app.inputs, {buffer_});
    return *this;
  }
  // A program with no inputs (a stencil over tables, a generator) runs
  // over the channel's own elements: out = blur;
  Channel& operator=(const Program& program) { return *this = Application{program, {}}; }

 private:
  std::shared_ptr<detail::Buffer> buffer_;
};

class Stream {
 public:
  Stream() = default;
  explicit Stream(std::vector<std::shared_ptr<detail::Buffer>> channels) : channels_(std::move(channels)) {}
  const std::vector<std::shared_ptr<detail::Buffer>>& channels() const { return channels_; }

  Stream& operator=(const Application& app) {
    run(app.program, app.inputs, channels_);
    return *this;
  }
  Stream& operator=(const Program& program) { return *this = Application{program, {}}; }

 private:
  std::vector<std::shared_ptr<detail::Buffer>> channels_;
};

template <class A, class B>
Stream operator&(const Channel<A>& a, const Channel<B>& b) {
  return Stream({a, b});
}
template <class B>
Stream operator&(const Stream& s, const Channel<B>& b) {
  auto channels = s.channels();
  channels.push_back(b);
  return Stream(std::move(channels));
}

inline Application operator<<(const Program& p, const Stream& inputs) { return {p, inputs.channels()}; }
template <class A>
Application operator<<(const Program& p, const Channel<A>& input) {
  return {p, {input}};
}

// p << u: binds p's first input to the uniform or constant u (Sh's algebra).
template <AttribLike A>
Program operator<<(const Program& p, const A& value) {
  return bind(p, value.value());
}

}  // namespace sh
