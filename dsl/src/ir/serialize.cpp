#include "sh/ir/serialize.hpp"

#include <cstring>

#include "sh/error.hpp"
#include "sh/ir/verifier.hpp"

namespace sh::ir {
namespace {

enum class Tag : std::uint8_t { Assign, If, Loop, Break, Continue, Scatter };

class Writer {
 public:
  template <class T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size()));
    out_ += s;
  }
  void put(const Swizzle& s) {
    put(static_cast<std::uint8_t>(s.size));
    for (int i = 0; i < s.size; ++i) put(s.index[i]);
  }
  void put(const Operand& o) {
    put(static_cast<std::int32_t>(o.var));
    put(o.swizzle);
  }
  void put(const std::vector<VarId>& ids) {
    put(static_cast<std::uint32_t>(ids.size()));
    for (VarId id : ids) put(static_cast<std::int32_t>(id));
  }
  void put(const Block& b) {
    put(static_cast<std::uint32_t>(b.size()));
    for (const Stmt& s : b) stmt(s);
  }
  std::string take() { return std::move(out_); }

 private:
  void stmt(const Stmt& s) {
    if (auto* a = std::get_if<Assign>(&s.node)) {
      put(Tag::Assign);
      put(static_cast<std::int32_t>(a->dest));
      put(a->mask);
      put(a->op);
      put(static_cast<std::int32_t>(a->table));
      put(static_cast<std::uint8_t>(a->args.size()));
      for (const Operand& o : a->args) put(o);
    } else if (auto* i = std::get_if<If>(&s.node)) {
      put(Tag::If);
      put(i->cond);
      put(i->then_body);
      put(i->else_body);
    } else if (auto* l = std::get_if<Loop>(&s.node)) {
      put(Tag::Loop);
      put(static_cast<std::uint8_t>(l->test_at_top));
      put(l->header);
      put(l->cond);
      put(l->body);
      put(l->update);
    } else if (auto* sc = std::get_if<Scatter>(&s.node)) {
      put(Tag::Scatter);
      put(static_cast<std::int32_t>(sc->table));
      put(sc->index);
      put(sc->value);
    } else {
      put(std::holds_alternative<Break>(s.node) ? Tag::Break : Tag::Continue);
    }
  }

  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}

  template <class T>
  T get() {
    T v;
    need(sizeof v);
    std::memcpy(&v, in_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::string text() {
    auto n = get<std::uint32_t>();
    need(n);
    std::string s = in_.substr(at_, n);
    at_ += n;
    return s;
  }
  Swizzle swizzle() {
    Swizzle s;
    s.size = get<std::uint8_t>();
    if (s.size > 4) fail("swizzle of more than 4 components");
    for (int i = 0; i < s.size; ++i) s.index[i] = get<std::uint8_t>();
    return s;
  }
  Operand operand() {
    Operand o;
    o.var = get<std::int32_t>();
    o.swizzle = swizzle();
    return o;
  }
  std::vector<VarId> ids() {
    auto n = get<std::uint32_t>();
    std::vector<VarId> out;
    for (std::uint32_t i = 0; i < n; ++i) out.push_back(get<std::int32_t>());
    return out;
  }
  Block block(int depth = 0) {
    if (depth > 10000) fail("statements nested too deeply");
    auto n = get<std::uint32_t>();
    Block b;
    for (std::uint32_t i = 0; i < n; ++i) b.push_back(stmt(depth));
    return b;
  }
  bool at_end() const { return at_ == in_.size(); }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("malformed program bytes at offset " + std::to_string(at_) + ": " + what);
  }

 private:
  void need(std::size_t n) const {
    if (in_.size() - at_ < n) fail("truncated");
  }

  Stmt stmt(int depth) {
    auto tag = get<Tag>();
    switch (tag) {
      case Tag::Assign: {
        Assign a;
        a.dest = get<std::int32_t>();
        a.mask = swizzle();
        a.op = get<Op>();
        if (static_cast<int>(a.op) >= kOpCount) fail("unknown operation");
        a.table = get<std::int32_t>();
        auto n = get<std::uint8_t>();
        for (int i = 0; i < n; ++i) a.args.push_back(operand());
        return Stmt{std::move(a)};
      }
      case Tag::If: {
        If i;
        i.cond = operand();
        i.then_body = block(depth + 1);
        i.else_body = block(depth + 1);
        return Stmt{std::move(i)};
      }
      case Tag::Loop: {
        Loop l;
        l.test_at_top = get<std::uint8_t>() != 0;
        l.header = block(depth + 1);
        l.cond = operand();
        l.body = block(depth + 1);
        l.update = block(depth + 1);
        return Stmt{std::move(l)};
      }
      case Tag::Break: return Stmt{Break{}};
      case Tag::Continue: return Stmt{Continue{}};
      case Tag::Scatter: {
        Scatter sc;
        sc.table = get<std::int32_t>();
        sc.index = operand();
        sc.value = operand();
        return Stmt{sc};
      }
    }
    fail("unknown statement");
  }

  const std::string& in_;
  std::size_t at_ = 0;
};

constexpr std::uint32_t kMagic = 0x53484952;  // "SHIR"

}  // namespace

std::string serialize(const Program& p) {
  Writer w;
  w.put(kMagic);
  w.put(p.name);
  w.put(static_cast<std::uint32_t>(p.vars.size()));
  for (const Var& v : p.vars) {
    w.put(v.kind);
    w.put(v.type.scalar);
    w.put(static_cast<std::uint8_t>(v.type.width));
    w.put(v.name);
    for (double x : v.value) w.put(x);
  }
  w.put(p.inputs);
  w.put(p.outputs);
  w.put(p.uniforms);
  w.put(static_cast<std::uint32_t>(p.tables.size()));
  for (const TableDecl& t : p.tables) {
    w.put(t.element.scalar);
    w.put(static_cast<std::uint8_t>(t.element.width));
    w.put(static_cast<std::uint8_t>(t.rank));
    w.put(t.name);
    w.put(static_cast<std::uint8_t>(t.accumulator));
  }
  w.put(p.body);
  return w.take();
}

Program deserialize(const std::string& bytes) {
  Reader r(bytes);
  if (r.get<std::uint32_t>() != kMagic) r.fail("not a serialized program");
  Program p;
  p.name = r.text();
  auto vars = r.get<std::uint32_t>();
  for (std::uint32_t i = 0; i < vars; ++i) {
    Var v;
    v.kind = r.get<VarKind>();
    v.type.scalar = r.get<Scalar>();
    v.type.width = r.get<std::uint8_t>();
    v.name = r.text();
    for (double& x : v.value) x = r.get<double>();
    if (v.kind > VarKind::Temp || v.type.scalar > Scalar::Bool) r.fail("unknown variable kind or type");
    p.vars.push_back(std::move(v));
  }
  p.inputs = r.ids();
  p.outputs = r.ids();
  p.uniforms = r.ids();
  auto tables = r.get<std::uint32_t>();
  for (std::uint32_t i = 0; i < tables; ++i) {
    TableDecl t;
    t.element.scalar = r.get<Scalar>();
    t.element.width = r.get<std::uint8_t>();
    t.rank = r.get<std::uint8_t>();
    t.name = r.text();
    t.accumulator = r.get<std::uint8_t>() != 0;
    if (t.element.scalar > Scalar::Bool || t.element.width < 1 || t.element.width > 4 || t.rank < 1 || t.rank > 3)
      r.fail("bad table declaration");
    p.tables.push_back(std::move(t));
  }
  p.body = r.block();
  if (!r.at_end()) r.fail("bytes after the program");
  verify(p);
  return p;
}

}  // namespace sh::ir
