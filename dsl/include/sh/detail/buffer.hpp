#pragma once
// Host memory behind channels and tables: `count` elements of one IR type,
// components contiguous per element.  Bools are stored as int32 0/1.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sh/ir/program.hpp"

namespace sh::detail {

class Buffer {
 public:
  Buffer() = default;
  Buffer(ir::Type type, std::size_t count) : type_(type) { resize(count); }

  ir::Type type() const { return type_; }
  std::size_t size() const { return count_; }
  std::size_t bytes() const { return count_ * type_.width * ir::storage_bytes(type_.scalar); }
  void resize(std::size_t count);
  void* data() { return words_.data(); }
  const void* data() const { return words_.data(); }

  // Component c of element i, as a double (exact for every stored type).
  double get(std::size_t i, int c) const;
  void set(std::size_t i, int c, double v);

 private:
  ir::Type type_;
  std::size_t count_ = 0;
  std::vector<std::uint64_t> words_;  // 8-byte aligned storage
};

struct TableStorage {
  TableStorage();
  std::uint64_t id;  // unique in the process, never reused
  ir::TableDecl decl;
  std::array<int, 3> dims{1, 1, 1};
  Buffer buffer;
  bool filled = false;
  std::uint64_t version = 0;  // bumped at every host write
};

}  // namespace sh::detail
