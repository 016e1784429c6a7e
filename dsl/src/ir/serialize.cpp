#include "sh/ir/serialize.hpp"

#include <bit>

#include "sh/error.hpp"
#include "sh/ir/verifier.hpp"
#include "../fnv1a.hpp"

namespace sh::ir {
namespace {

enum class Tag : std::uint8_t { Assign, If, Loop, Break, Continue, Scatter, Prefetch };
constexpr int kTagCount = 7;

constexpr char kMagic[] = "SHIR";
// Bumped whenever the layout or the meaning of a number in it (the op
// table's order among them) changes, so old bytes are refused, not misread.
// An array variable (kind 6, its length after its name) reads as nothing
// older did, so programs without one keep their bytes and hashes.
constexpr std::uint8_t kVersion = 3;  // 3: a table's edge mode

class Writer {
 public:
  explicit Writer(const SerializeOptions& o) : names_(o.names) {}

  void u8(unsigned v) { out_ += static_cast<char>(v & 0xff); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) u8(v >> (8 * i));
  }
  void i32(int v) { u32(static_cast<std::uint32_t>(v)); }
  void f64(double v) {
    auto bits = std::bit_cast<std::uint64_t>(v);
    u32(static_cast<std::uint32_t>(bits));
    u32(static_cast<std::uint32_t>(bits >> 32));
  }
  void name(const std::string& s) {
    if (!names_) return u32(0);
    u32(static_cast<std::uint32_t>(s.size()));
    out_ += s;
  }
  void count(std::size_t n) { u32(static_cast<std::uint32_t>(n)); }
  void text(const char* raw) { out_ += raw; }
  void type(Type t) {
    u8(static_cast<unsigned>(t.scalar));
    u8(static_cast<unsigned>(t.width));
  }
  void swizzle(const Swizzle& s) {
    u8(static_cast<unsigned>(s.size));
    for (int i = 0; i < s.size; ++i) u8(s.index[i]);
  }
  void operand(const Operand& o) {
    i32(o.var);
    swizzle(o.swizzle);
  }
  void ids(const std::vector<VarId>& list) {
    count(list.size());
    for (VarId id : list) i32(id);
  }
  void block(const Block& b) {
    count(b.size());
    for (const Stmt& s : b) stmt(s);
  }
  std::string take() { return std::move(out_); }

 private:
  void tag(Tag t) { u8(static_cast<unsigned>(t)); }

  void stmt(const Stmt& s) {
    if (auto* a = std::get_if<Assign>(&s.node)) {
      tag(Tag::Assign);
      i32(a->dest);
      swizzle(a->mask);
      u8(static_cast<unsigned>(a->op));
      i32(a->table);
      u8(static_cast<unsigned>(a->args.size()));
      for (const Operand& o : a->args) operand(o);
    } else if (auto* i = std::get_if<If>(&s.node)) {
      tag(Tag::If);
      operand(i->cond);
      block(i->then_body);
      block(i->else_body);
    } else if (auto* l = std::get_if<Loop>(&s.node)) {
      tag(Tag::Loop);
      u8(l->test_at_top ? 1 : 0);
      block(l->header);
      operand(l->cond);
      block(l->body);
      block(l->update);
    } else if (auto* sc = std::get_if<Scatter>(&s.node)) {
      tag(Tag::Scatter);
      i32(sc->table);
      operand(sc->index);
      operand(sc->value);
    } else if (auto* pf = std::get_if<Prefetch>(&s.node)) {
      tag(Tag::Prefetch);
      i32(pf->table);
      operand(pf->index);
    } else {
      tag(std::holds_alternative<Break>(s.node) ? Tag::Break : Tag::Continue);
    }
  }

  bool names_;
  std::string out_;
};

// Every read names what it reads, so that an error says where the bytes
// went wrong; every value is checked against its range before it is used.
class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}

  unsigned u8(const char* what) {
    need(1, what);
    return static_cast<unsigned char>(in_[at_++]);
  }
  std::uint32_t u32(const char* what) {
    need(4, what);
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(in_[at_ + i])) << (8 * i);
    at_ += 4;
    return v;
  }
  double f64(const char* what) {
    need(8, what);
    std::uint64_t lo = u32(what);
    std::uint64_t hi = u32(what);
    return std::bit_cast<double>(lo | hi << 32);
  }
  bool flag(const char* what) {
    unsigned v = u8(what);
    if (v > 1) fail(std::string(what) + " is " + std::to_string(v) + ", not 0 or 1");
    return v == 1;
  }
  // A value in [lo, hi).
  int ranged(std::int64_t v, int lo, int hi, const char* what) {
    if (v < lo || v >= hi)
      fail(std::string(what) + " is " + std::to_string(v) + ", outside [" + std::to_string(lo) + ", " +
           std::to_string(hi) + ")");
    return static_cast<int>(v);
  }
  int i32_in(int lo, int hi, const char* what) {
    return ranged(static_cast<std::int32_t>(u32(what)), lo, hi, what);
  }
  // A count of items of at least `min_bytes` each, which the bytes left
  // could hold (so a garbled count fails here, not after a huge allocation).
  std::uint32_t count(std::size_t min_bytes, const char* what) {
    std::uint32_t n = u32(what);
    if (n > (in_.size() - at_) / min_bytes) fail(std::string(what) + " " + std::to_string(n) + " exceeds the bytes left");
    return n;
  }
  std::string name(const char* what) {
    std::uint32_t n = count(1, what);
    std::string s = in_.substr(at_, n);
    at_ += n;
    return s;
  }
  Type type(const char* what) {
    Type t;
    t.scalar = static_cast<Scalar>(ranged(u8(what), 0, static_cast<int>(Scalar::Bool) + 1, what));
    t.width = ranged(u8(what), 1, 5, what);
    return t;
  }
  void expect_magic() {
    need(4, "magic");
    if (in_.compare(at_, 4, kMagic) != 0) fail("not a serialized program (it does not start with SHIR)");
    at_ += 4;
  }
  void expect_end() {
    value_at_ = at_;
    if (at_ != in_.size()) fail(std::to_string(in_.size() - at_) + " bytes after the program");
  }
  // Names the offset of the value read last (where it went wrong).
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("malformed program bytes at offset " + std::to_string(value_at_) + ": " + what);
  }

 private:
  void need(std::size_t n, const char* what) {
    value_at_ = at_;
    if (in_.size() - at_ < n) fail(std::string("truncated in ") + what);
  }

  const std::string& in_;
  std::size_t at_ = 0, value_at_ = 0;
};

// The program's parts in the order serialize writes them, each read value
// checked against what the parts read before it declared.
class ProgramReader {
 public:
  explicit ProgramReader(const std::string& bytes) : r_(bytes) {}

  Program read() {
    header();
    p_.name = r_.name("program name");
    vars();
    p_.inputs = ids("input list");
    p_.outputs = ids("output list");
    p_.uniforms = ids("uniform list");
    tables();
    p_.body = block(0);
    r_.expect_end();
    verify(p_);
    return std::move(p_);
  }

 private:
  void header() {
    r_.expect_magic();
    unsigned version = r_.u8("version");
    if (version != kVersion)
      r_.fail("format version " + std::to_string(version) + "; this build reads version " + std::to_string(kVersion));
  }

  void vars() {
    std::uint32_t n = r_.count(7, "variable count");
    for (std::uint32_t i = 0; i < n; ++i) {
      Var v;
      v.kind = static_cast<VarKind>(r_.ranged(r_.u8("variable kind"), 0, static_cast<int>(VarKind::Array) + 1,
                                              "variable kind"));
      v.type = r_.type("variable type");
      v.name = r_.name("variable name");
      if (v.kind == VarKind::Array) v.length = r_.i32_in(1, kMaxArrayLength + 1, "array length");
      if (v.kind == VarKind::Const)
        for (int c = 0; c < v.type.width; ++c) v.value[c] = r_.f64("constant component");
      p_.vars.push_back(std::move(v));
    }
  }

  std::vector<VarId> ids(const char* what) {
    std::uint32_t n = r_.count(4, what);
    std::vector<VarId> out;
    for (std::uint32_t i = 0; i < n; ++i) out.push_back(var_id(what));
    return out;
  }

  VarId var_id(const char* what) { return r_.i32_in(0, static_cast<int>(p_.vars.size()), what); }

  void tables() {
    std::uint32_t n = r_.count(8, "table count");
    for (std::uint32_t i = 0; i < n; ++i) {
      TableDecl t;
      t.element = r_.type("table element type");
      t.rank = r_.ranged(r_.u8("table rank"), 1, 4, "table rank");
      t.name = r_.name("table name");
      t.accumulator = r_.flag("table accumulator flag");
      t.edge = static_cast<Edge>(r_.ranged(r_.u8("table edge mode"), 0, 3, "table edge mode"));
      p_.tables.push_back(std::move(t));
    }
  }

  Swizzle swizzle(const char* what) {
    Swizzle s;
    s.size = r_.ranged(r_.u8(what), 1, 5, what);
    for (int i = 0; i < s.size; ++i) s.index[i] = static_cast<std::uint8_t>(r_.ranged(r_.u8(what), 0, 4, what));
    return s;
  }

  Operand operand(const char* what) {
    Operand o;
    o.var = var_id(what);
    o.swizzle = swizzle("operand swizzle");
    return o;
  }

  Block block(int depth) {
    if (depth > kMaxNesting) r_.fail("statements nested deeper than " + std::to_string(kMaxNesting));
    std::uint32_t n = r_.count(1, "statement count");
    Block b;
    for (std::uint32_t i = 0; i < n; ++i) b.push_back(stmt(depth));
    return b;
  }

  Stmt stmt(int depth) {
    switch (static_cast<Tag>(r_.ranged(r_.u8("statement tag"), 0, kTagCount, "statement tag"))) {
      case Tag::Assign: return Stmt{assign()};
      case Tag::If: {
        If i;
        i.cond = operand("condition");
        i.then_body = block(depth + 1);
        i.else_body = block(depth + 1);
        return Stmt{std::move(i)};
      }
      case Tag::Loop: {
        Loop l;
        l.test_at_top = r_.flag("loop test-first flag");
        l.header = block(depth + 1);
        l.cond = operand("loop condition");
        l.body = block(depth + 1);
        l.update = block(depth + 1);
        return Stmt{std::move(l)};
      }
      case Tag::Break: return Stmt{Break{}};
      case Tag::Continue: return Stmt{Continue{}};
      case Tag::Scatter: {
        Scatter sc;
        sc.table = r_.i32_in(0, static_cast<int>(p_.tables.size()), "scatter table");
        sc.index = operand("scatter index");
        sc.value = operand("scatter value");
        return Stmt{sc};
      }
      case Tag::Prefetch: {
        Prefetch pf;
        pf.table = r_.i32_in(0, static_cast<int>(p_.tables.size()), "prefetch table");
        pf.index = operand("prefetch index");
        return Stmt{pf};
      }
    }
    r_.fail("unknown statement");  // unreachable: the tag was range-checked
  }

  Assign assign() {
    Assign a;
    a.dest = var_id("destination");
    a.mask = swizzle("write mask");
    a.op = static_cast<Op>(r_.u8("operation"));
    if (static_cast<int>(a.op) >= kOpCount) r_.fail("unknown operation");
    a.table = r_.i32_in(-1, static_cast<int>(p_.tables.size()), "table");
    int n = r_.u8("operand count");
    if (n != op_arity(a.op))
      r_.fail(std::string(op_name(a.op)) + " takes " + std::to_string(op_arity(a.op)) + " operands, not " +
              std::to_string(n));
    for (int i = 0; i < n; ++i) a.args.push_back(operand("operand"));
    return a;
  }

  Reader r_;
  Program p_;
};

}  // namespace

std::string serialize(const Program& p, const SerializeOptions& options) {
  Writer w(options);
  w.text(kMagic);
  w.u8(kVersion);
  w.name(p.name);
  w.count(p.vars.size());
  for (const Var& v : p.vars) {
    w.u8(static_cast<unsigned>(v.kind));
    w.type(v.type);
    w.name(v.name);
    if (v.kind == VarKind::Array) w.i32(v.length);
    if (v.kind == VarKind::Const)
      for (int c = 0; c < v.type.width && c < 4; ++c) w.f64(v.value[c]);
  }
  w.ids(p.inputs);
  w.ids(p.outputs);
  w.ids(p.uniforms);
  w.count(p.tables.size());
  for (const TableDecl& t : p.tables) {
    w.type(t.element);
    w.u8(static_cast<unsigned>(t.rank));
    w.name(t.name);
    w.u8(t.accumulator ? 1 : 0);
    w.u8(static_cast<unsigned>(t.edge));
  }
  w.block(p.body);
  return w.take();
}

Program deserialize(const std::string& bytes) { return ProgramReader(bytes).read(); }

std::uint64_t structural_hash(const Program& p) { return sh::detail::fnv1a(serialize(p, {.names = false})); }

}  // namespace sh::ir
