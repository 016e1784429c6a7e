#include "sh/detail/value.hpp"

#include "recorder.hpp"
#include "sh/library.hpp"
#include "sh/error.hpp"

namespace sh::detail {
namespace {

[[noreturn]] void host_fail(const std::string& what) { throw Error("outside any program: " + what); }

std::shared_ptr<VarNode> new_node(ir::VarKind kind, ir::Type type) {
  auto node = std::make_shared<VarNode>();
  node->kind = kind;
  node->type = type;
  return node;
}

Value whole(std::shared_ptr<VarNode> node) {
  ir::Swizzle s = ir::Swizzle::identity(node->type.width);
  return Value{std::move(node), s};
}

// Component i of the operand as the operation sees it (width-1 broadcasts).
double host_component(const Value& v, int i) {
  if (v.node->kind != ir::VarKind::Uniform && v.node->kind != ir::VarKind::Const) {
    // Inside a program too: get() of an input, an output or a temporary.
    const std::string what = "a host value was asked of a program variable" +
                             (v.node->name.empty() ? std::string() : " '" + v.node->name + "'") +
                             " (an input, an output or a temporary has values only as the program runs; uniforms "
                             "and constants have one on the host)";
    if (Recorder* r = current_recorder()) r->fail(what);
    host_fail(what);
  }
  return v.node->value[v.swizzle[v.width() == 1 ? 0 : i]];
}

[[noreturn]] void type_mismatch(ir::Op op, const Value& a, const Value& b) {
  std::string what = std::string("type mismatch: ") + ir::op_name(op) + " of " + ir::type_name(a.type()) +
                     " and " + ir::type_name(b.type());
  if (Recorder* r = current_recorder()) r->fail(what);
  host_fail(what);
}

}  // namespace

bool recording() { return current_recorder() != nullptr; }

Value declare(ir::Type type, Declared how) {
  Recorder* r = current_recorder();
  if (!r) {
    if (how != Declared::Temp) host_fail("inputs and outputs can only be declared inside a program");
    return whole(new_node(ir::VarKind::Uniform, type));
  }
  static constexpr ir::VarKind kinds[] = {ir::VarKind::Temp, ir::VarKind::Input, ir::VarKind::Output,
                                          ir::VarKind::InOut};
  auto node = new_node(kinds[static_cast<int>(how)], type);
  r->declare(node, how);
  return whole(std::move(node));
}

Value constant(ir::Type type, const std::array<double, 4>& components) {
  auto node = new_node(ir::VarKind::Const, type);
  for (int i = 0; i < type.width; ++i) node->value[i] = ir::hold(type.scalar, ir::Precision::F32, components[i]);
  if (type.scalar == ir::Scalar::I32)
    for (int i = 0; i < type.width; ++i) node->value[i] = ir::to_int32(components[i]);
  if (type.scalar == ir::Scalar::Bool)
    for (int i = 0; i < type.width; ++i) node->value[i] = components[i] > 0 ? 1 : 0;
  return whole(std::move(node));
}

Value constant(ir::Scalar scalar, double v) { return constant({scalar, 1}, {v, v, v, v}); }

void assign(const Value& dest, const Value& src) {
  if (src.width() != 1 && src.width() != dest.width())
    throw Error("assignment of " + std::to_string(src.width()) + " components to " + std::to_string(dest.width()));
  // Another scalar type converts, as in Sh: a cast, then the copy.
  Value from = as_scalar(src, dest.scalar());
  if (Recorder* r = current_recorder()) {
    ir::Operand operand = r->read(from);
    ir::VarId target = r->write_target(dest);
    r->emit(ir::Assign{target, dest.swizzle, ir::Op::Mov, {operand}, -1});
    return;
  }
  if (dest.node->kind != ir::VarKind::Uniform) host_fail("a program variable is written on the host");
  std::array<double, 4> v{};
  for (int i = 0; i < dest.width(); ++i) v[i] = host_component(from, i);
  for (int i = 0; i < dest.width(); ++i) dest.node->value[dest.swizzle[i]] = v[i];
  ++dest.node->version;
}

Value apply(ir::Op op, std::initializer_list<Value> args) {
  const Value& first = *args.begin();
  int width = 1;
  for (const Value& a : args) {
    if (a.scalar() != first.scalar()) type_mismatch(op, first, a);
    if (a.width() != 1 && width != 1 && a.width() != width) type_mismatch(op, first, a);
    width = std::max(width, a.width());
  }
  if (!ir::accepts(op, first.scalar())) {
    std::string what = std::string(ir::op_name(op)) + " of " + ir::type_name(first.type()) + ": " + ir::op_name(op) +
                       " takes " + ir::domain_name(ir::op_info(op).domain) + "; convert the operand first (cast<float>())";
    if (Recorder* r = current_recorder()) r->fail(what);
    host_fail(what);
  }
  ir::Type type{first.scalar(), width};
  if (Recorder* r = current_recorder()) {
    std::vector<ir::Operand> operands;
    for (const Value& a : args) operands.push_back(r->read(a));
    return r->emit_result(type, op, std::move(operands));
  }
  auto node = new_node(ir::VarKind::Uniform, type);
  std::vector<Value> a(args);
  for (int i = 0; i < width; ++i) {
    double x[3] = {0, 0, 0};
    for (std::size_t k = 0; k < a.size(); ++k) x[k] = host_component(a[k], i);
    node->value[i] = ir::eval(op, type.scalar, type.scalar, ir::Precision::F32, x[0], x[1], x[2]);
  }
  return whole(std::move(node));
}

Value copy(const Value& v) {
  if (Recorder* r = current_recorder()) return r->emit_result(v.type(), ir::Op::Mov, {r->read(v)});
  auto node = new_node(ir::VarKind::Uniform, v.type());
  for (int i = 0; i < v.width(); ++i) node->value[i] = host_component(v, i);
  return whole(std::move(node));
}

Value cast(const Value& v, ir::Scalar to) {
  if (v.scalar() == to) return copy(v);
  ir::Type type{to, v.width()};
  if (Recorder* r = current_recorder()) return r->emit_result(type, ir::Op::Cast, {r->read(v)});
  auto node = new_node(ir::VarKind::Uniform, type);
  for (int i = 0; i < v.width(); ++i)
    node->value[i] = ir::eval(ir::Op::Cast, v.scalar(), to, ir::Precision::F32, host_component(v, i));
  return whole(std::move(node));
}

Value swizzle(const Value& v, std::initializer_list<int> components) {
  Value out = v;
  out.swizzle.size = static_cast<int>(components.size());
  int i = 0;
  for (int c : components) {
    if (c < 0 || c >= v.width()) {
      std::string what = "swizzle index " + std::to_string(c) + " is out of range for a " +
                         std::to_string(v.width()) + "-component value";
      if (Recorder* r = current_recorder()) r->fail(what);
      host_fail(what);
    }
    out.swizzle.index[i++] = v.swizzle[c];
  }
  return out;
}

Value component(const Value& v, int i) { return swizzle(v, {i}); }

Value as_scalar(const Value& v, ir::Scalar to) { return v.scalar() == to ? v : cast(v, to); }

Value widened(const Value& v, int width) {
  Value out = v;
  out.swizzle.size = width;
  for (int i = 0; i < width; ++i) out.swizzle.index[i] = v.swizzle[std::min(i, v.width() - 1)];
  return out;
}

std::array<double, 4> host_value(const Value& v) {
  std::array<double, 4> out{};
  for (int i = 0; i < v.width(); ++i) out[i] = host_component(v, i);
  return out;
}

void set_name(const Value& v, const std::string& name) {
  v.node->name = name;
  if (Recorder* r = current_recorder()) r->rename(v.node.get(), name);
}

Value table_read(const std::shared_ptr<TableStorage>& table, ir::Op op, const Value& coords) {
  Recorder* r = current_recorder();
  if (!r) host_fail("tables can only be read inside a program");
  if (coords.width() != table->decl.rank)
    r->fail("table '" + table->decl.name + "' has " + std::to_string(table->decl.rank) + " dimensions but is read with " +
            std::to_string(coords.width()) + " coordinates");
  Value c = op == ir::Op::Fetch ? as_scalar(coords, ir::Scalar::I32) : coords;
  if (op == ir::Op::Sample && !ir::is_float(c.scalar())) c = cast(c, ir::Scalar::F32);
  return r->emit_result(table->decl.element, op, {r->read(c)}, r->table_index(table));
}

void table_prefetch(const std::shared_ptr<TableStorage>& table, const Value& coords) {
  Recorder* r = current_recorder();
  if (!r) host_fail("a prefetch brings a table's element near a program's reads, so it can only be asked inside a program");
  if (coords.width() != table->decl.rank)
    r->fail("table '" + table->decl.name + "' has " + std::to_string(table->decl.rank) + " dimensions but is prefetched with " +
            std::to_string(coords.width()) + " coordinates");
  r->emit_prefetch(ir::Prefetch{r->table_index(table), r->read(as_scalar(coords, ir::Scalar::I32))});
}

Value position(int dimensions) {
  Recorder* r = current_recorder();
  if (!r) host_fail("position() names an element of a run, so it can only be read inside a program");
  if (dimensions < 1 || dimensions > 3) r->fail("position<" + std::to_string(dimensions) + ">(): a launch domain has 1 to 3 dimensions");
  return r->emit_result({ir::Scalar::I32, dimensions}, ir::Op::Position, {});
}

Value declare_array(ir::Type element, int length) {
  Recorder* r = current_recorder();
  if (!r) host_fail("a local array belongs to a program's elements, so it can only be declared inside a program");
  if (length < 1 || length > ir::kMaxArrayLength)
    r->fail("a local array holds 1 to " + std::to_string(ir::kMaxArrayLength) + " elements, not " + std::to_string(length));
  auto node = new_node(ir::VarKind::Array, element);
  node->length = length;
  r->declare(node, Declared::Temp);
  return whole(std::move(node));
}

Value array_element(const Value& array, const Value& index) {
  Recorder* r = current_recorder();
  if (!r) host_fail("local arrays can only be read inside a program");
  if (index.width() != 1) r->fail("a local array is indexed by one integer, not " + std::to_string(index.width()) + " components");
  return r->emit_result(array.type(), ir::Op::Element, {r->read(array), r->read(as_scalar(index, ir::Scalar::I32))});
}

void array_store(const Value& array, const Value& index, const Value& value) {
  Recorder* r = current_recorder();
  if (!r) host_fail("local arrays can only be written inside a program");
  std::string what = "a local array of " + ir::type_name(array.type());
  if (index.width() != 1) r->fail(what + " is indexed by one integer, not " + std::to_string(index.width()) + " components");
  if (value.width() != array.width() && value.width() != 1)
    r->fail(what + " is given a value of " + std::to_string(value.width()) + " components");
  ir::Operand at = r->read(as_scalar(index, ir::Scalar::I32));
  ir::Operand v = r->read(widened(as_scalar(value, array.scalar()), array.width()));
  r->emit(ir::Assign{r->write_target(array), ir::Swizzle::identity(array.width()), ir::Op::Store, {at, v}, -1});
}

void array_fill(const Value& array, const Value& value) {
  Recorder* r = current_recorder();
  if (!r) host_fail("local arrays can only be written inside a program");
  ir::Operand v = r->read(widened(as_scalar(value, array.scalar()), array.width()));
  r->emit(ir::Assign{r->write_target(array), ir::Swizzle::identity(array.width()), ir::Op::Fill, {v}, -1});
}

void scatter_add(const std::shared_ptr<TableStorage>& accumulator, const Value& index, const Value& value) {
  Recorder* r = current_recorder();
  if (!r) host_fail("accumulators can only be added into inside a program");
  const ir::TableDecl& d = accumulator->decl;
  std::string what = "accumulator '" + d.name + "' of " + ir::type_name(d.element);
  if (index.width() != d.rank)
    r->fail(what + " is indexed with " + std::to_string(index.width()) + " coordinates, not " + std::to_string(d.rank));
  if (value.width() != d.element.width && value.width() != 1)
    r->fail(what + " is given a value of " + std::to_string(value.width()) + " components");
  if (value.scalar() != d.element.scalar) r->fail(what + " is given a value of type " + ir::scalar_name(value.scalar()));
  Value v = widened(value, d.element.width);
  r->emit_scatter(ir::Scatter{r->table_index(accumulator), r->read(as_scalar(index, ir::Scalar::I32)), r->read(v)});
}

void no_component(int i, int width) {
  throw Error("component " + std::to_string(i) + " of a value of " + std::to_string(width) + " (they are 0 to " +
              std::to_string(width - 1) + ")");
}

void ValueHolder::moved_from() {
  throw Error("an Attrib was read after std::move took its variable: assign it a value before reading it again");
}

}  // namespace sh::detail
