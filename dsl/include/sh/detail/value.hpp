#pragma once
// The untyped core under Attrib<N, T, S>: a variable node and a swizzle.
// Every operation of the language goes through the functions here, which
// record an assignment while a program is being recorded and compute the
// result on the host otherwise (uniform arithmetic between runs).
#include <array>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "sh/ir/eval.hpp"
#include "sh/ir/program.hpp"

namespace sh::detail {

class Recorder;

struct VarNode {
  ir::VarKind kind = ir::VarKind::Temp;
  ir::Type type;
  std::string name;
  std::array<double, 4> value{};  // host value of a uniform or constant
  std::uint64_t version = 0;      // bumped at every host write of a uniform
  std::uint64_t recording = 0;      // the recording a non-uniform belongs to (Recorder::serial)
  int length = 0;                   // an array's elements (kind Array)
};

struct Value {
  std::shared_ptr<VarNode> node;
  ir::Swizzle swizzle;

  int width() const { return swizzle.size; }
  ir::Scalar scalar() const { return node->type.scalar; }
  ir::Type type() const { return {scalar(), width()}; }
};

enum class Declared { Temp, Input, Output, InOut };

// A new variable: a temporary (or input, output) inside a recording; outside
// one a temporary is a uniform whose value the host sets.
Value declare(ir::Type type, Declared how);
Value constant(ir::Type type, const std::array<double, 4>& components);
Value constant(ir::Scalar scalar, double v);

// dest (through its swizzle as write mask) = src; src of width 1 broadcasts.
void assign(const Value& dest, const Value& src);

// Component-wise operation; the result's width is the widest operand's.
Value apply(ir::Op op, std::initializer_list<Value> args);
// A new variable holding v's value (v converted to `to`): writing the
// result never writes v, even where nothing needs converting.
Value copy(const Value& v);
Value cast(const Value& v, ir::Scalar to);
// Views of v, for reading only: v itself where it is already of scalar
// `to`; v's components with its last one repeated up to `width`.
Value as_scalar(const Value& v, ir::Scalar to);
Value widened(const Value& v, int width);
Value swizzle(const Value& v, std::initializer_list<int> components);
Value component(const Value& v, int i);

// The element's position in the launch domain, its first `dimensions`
// coordinates (i32); only inside a program.
Value position(int dimensions);

// A local array of `length` elements of `element` (zero at the start of
// every element), its element at an i32 index, and a store into it; only
// inside a program.
Value declare_array(ir::Type element, int length);
Value array_element(const Value& array, const Value& index);
void array_store(const Value& array, const Value& index, const Value& value);
void array_fill(const Value& array, const Value& value);

// Host-side access to a uniform or constant (outside recording).
std::array<double, 4> host_value(const Value& v);
// Throws sh::Error: component `i` asked of a value of `width` components.
[[noreturn]] void no_component(int i, int width);
void set_name(const Value& v, const std::string& name);

bool recording();

}  // namespace sh::detail

namespace sh::detail {
struct TableStorage;
// Reads `table` at `coords` (Fetch: int32 element indices; Sample: [0, 1]).
Value table_read(const std::shared_ptr<TableStorage>& table, ir::Op op, const Value& coords);
void table_prefetch(const std::shared_ptr<TableStorage>& table, const Value& coords);
}  // namespace sh::detail
