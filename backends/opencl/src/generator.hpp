#pragma once
// The generator of one kernel of an OpenCL C source (codegen.hpp says what
// a source holds).  Its parts, by job: generator.cpp (the kernel's frame,
// which registers are uniform or truth values, a stencil's two bodies),
// text.cpp (the text that differs between the forms, the prelude's helper
// functions, types, names and operands), statements.cpp (control flow,
// branching or under masks), assignments.cpp (operations) and tables.cpp
// (table reads, local arrays, scatters).
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "sh/analysis.hpp"
#include "sh/backend.hpp"

namespace sh::opencl {

inline constexpr char kComponent[] = "xyzw";
inline constexpr char kLaneDigit[] = "0123456789abcdef";

// A user's name as the text of a `//` comment: a backslash there (or the
// trigraph ??/) would continue the comment onto the next line, and a line
// break would end it, so that the rest of the name became source; each of
// these characters, and '?', is written '_'.
std::string comment_text(const std::string& name);

// What the kernels of one source share: the helper functions written once
// before them, and whether the source needs double precision.
struct Prelude {
  std::set<std::string> names;
  std::string text;
  bool needs_fp64 = false;
};

// One kernel of the source: the scalar form (lanes 1: a work-item runs one
// element, with C's control flow) or the SPMD form (a work-item runs
// `lanes` consecutive elements in vector registers, the control flow as
// masks: an assignment under a mask selects, a branch side runs when any
// lane takes it, a loop runs while any lane loops).  The two differ only
// in the text of types, choices and the statements that steer lanes.
class Generator {
 public:
  Generator(const ir::Program& p, const sh::Options& o, int lanes, std::uint64_t largest_buffer, Prelude& prelude);
  std::string run(const char* name);

 private:
  // ---- the kernel's frame, uniformity and the stencil's bodies (generator.cpp) ------------------
  bool spmd() const { return lanes_ > 1; }
  // SPMD: whether lanes may hold different values of v (otherwise every
  // lane holds lane 0's), and whether an if or loop needs masks.
  bool varying(ir::VarId v) const { return !spmd() || facts_.varying[v]; }
  bool scalar_register(ir::VarId v) const;
  bool divergent(const ir::Stmt& s) const { return spmd() && facts_.divergent.at(&s); }
  analysis::VarSet truth_registers() const;
  bool reads_truth(const ir::Assign& a, ir::VarId v, const analysis::VarSet& truth) const;
  bool gives_truth(const ir::Assign& a, const analysis::VarSet& truth) const;
  bool truth_operand(const ir::Operand& o, const analysis::VarSet& truth) const;
  std::string position() const;
  void stencil_or_body();
  std::string taps_inside() const;
  std::string tap(const ir::Assign& a, int c) const;

  // ---- text that differs between the forms (text.cpp) -------------------------------------------
  std::string vec(const std::string& scalar) const { return spmd() ? scalar + std::to_string(lanes_) : scalar; }
  std::string iota(const std::string& scalar) const;
  static std::string lane(int k) { return std::string(".s") + kLaneDigit[k]; }
  std::string bit(const std::string& comparison, ir::Scalar s) const;
  std::string choose(const std::string& comparison, const std::string& yes, const std::string& no, ir::Scalar s) const;
  // The integer type whose lanes select values of type `s`.
  const char* mask_type(ir::Scalar s) const { return std::string(reg_type(s)) == "double" ? "long" : "int"; }
  std::string bits_as(const char* type, const std::string& x) const { return "as_" + vec(type) + "(" + x + ")"; }
  std::string convert(const char* type, const std::string& x) const;
  std::string constant(ir::Scalar s, double v) const;

  // ---- the source's prelude (text.cpp) ----------------------------------------------------------
  std::string hidden_constants() const;
  std::string run_load(const std::string& element) const;
  std::string run_store(const std::string& element) const;
  std::string unaligned(const std::string& element) const;
  std::string helper(const std::string& name, const std::string& returns, const std::string& rest) const;
  std::string floor_remainder(ir::Scalar s) const;
  std::string round_half_up(ir::Scalar s) const;
  std::string bits_or(const std::string& scalar) const;
  std::string same_index() const;
  // Whether a mask has a lane set.
  std::string any(const std::string& mask) const { return "(" + bits_or("int") + "(" + mask + ") != 0)"; }
  std::string first_lane() const;

  // ---- types and names (text.cpp) ---------------------------------------------------------------
  const char* reg_type(ir::Scalar s) const;
  static const char* storage_type(ir::Scalar s);
  ir::Scalar scalar_of(ir::VarId v) const { return p_.type_of(v).scalar; }
  std::string reg(ir::VarId v, int c) const { return "v" + std::to_string(v) + "_" + kComponent[c]; }
  std::string number(ir::Scalar s, double v) const;
  std::string read(const ir::Operand& o, int i) const;
  std::string written(const ir::Operand& o, int i) const;
  std::string mask_of(const ir::Operand& o, int i) const;
  void line(int depth, const std::string& text) { body_ << std::string(2 * depth, ' ') << text << "\n"; }

  // ---- signature, registers, inputs, outputs (generator.cpp) ------------------------------------
  void signature(std::ostringstream& out);
  void registers();
  void array_registers(ir::VarId v);
  std::string at(const std::string& stream, int w, int c, int k) const;
  void load_inputs();
  void store_outputs();

  // ---- statements (statements.cpp) --------------------------------------------------------------
  void block(const ir::Block& b, int depth);
  void leave(bool is_break, int depth);
  std::string truthy(const ir::Operand& o) const;
  std::string lanes_where(const ir::Operand& o) const { return exec_mask(mask_of(o, 0)); }
  // The lanes where a comparison holds, as a mask of the exec mask's type.
  std::string exec_mask(const std::string& comparison) const { return "convert_" + vec("int") + "(" + comparison + ")"; }
  void branch(const ir::If& s, int depth);
  void masked_branch(const ir::If& s, const ir::Stmt& at, int depth);
  void side(const ir::Block& body, const analysis::VarSet& live, int depth);
  void enter_masked(const analysis::VarSet& live);
  bool masked() const { return !keep_.empty(); }
  void count_iteration(int number, const std::string& counter, const std::string& element, int depth);
  void loop(const ir::Loop& l, const ir::Stmt& s, int depth);
  void branching_loop(const ir::Loop& l, const ir::Stmt& s, int depth, const std::string& element);
  void masked_loop(const ir::Loop& l, const ir::Stmt& s, int depth);

  // ---- assignments (assignments.cpp) ------------------------------------------------------------
  void assign(const ir::Assign& a, int depth);
  void vote_once(const ir::Assign& a, int depth);
  void assign_in_form(const ir::Assign& a, int depth);
  std::string operation(ir::Op op, ir::Scalar from, ir::Scalar to, const std::string& a, const std::string& b,
                        const std::string& c) const;
  // Whether `test` holds in a running lane: a vote across the lanes.
  std::string voted(const std::string& test) const { return any("(" + exec_mask(test) + " & exec)"); }
  std::string truth_test(const ir::Assign& a, int i) const;
  static std::string compare(ir::Op op, const std::string& a, const std::string& b);
  std::string lane_by_lane(const std::string& f, const std::vector<std::string>& args, ir::Scalar s) const;
  std::string is_nan(const std::string& a, ir::Scalar s) const;
  std::string float_to_int(const std::string& a, ir::Scalar from) const;
  std::string nan_through(const std::string& f, const std::string& a, ir::Scalar s) const;
  std::string cast(const std::string& a, ir::Scalar from, ir::Scalar to) const;

  // ---- table reads (tables.cpp) -----------------------------------------------------------------
  std::string flat_index(int table, const ir::Operand& coord, bool clamp_inside = false) const;
  void table_read(const ir::Assign& a, std::string* results, int depth);

  // ---- local arrays (tables.cpp) ----------------------------------------------------------------
  std::string index_of(const ir::Operand& o, int k) const;
  void array_element(const ir::Assign& a, std::string* results);
  void array_store(const ir::Assign& a, int depth);
  void array_fill(const ir::Assign& a, int depth);
  // The exec mask as a select between values of scalar `s` takes it.
  std::string exec_for(ir::Scalar s) const { return std::string(mask_type(s)) == "int" ? "exec" : convert("long", "exec"); }
  void scatter(const ir::Scatter& sc, int depth);
  void prefetch(const ir::Prefetch& pf, int depth);

  // A masked loop's active mask, or how a branching loop is left.

  struct LoopExit {
    std::string active;
    bool wrapped;
    std::string flag;
  };

  const ir::Program& p_;
  const sh::Options& o_;
  int lanes_;  // 1 while a scalar register's value is written (assign)
  // Table elements are numbered in int where no buffer the device allows
  // holds more than INT_MAX of them (every element is 4 bytes or more): a
  // CPU device's gathers then take 32-bit indices, twice the lanes of
  // 64-bit ones a gather instruction.
  const char* index_type_;
  Prelude& prelude_;
  std::unordered_map<const ir::Assign*, analysis::ReadAccess> access_;
  std::ostringstream body_;
  mutable bool uses_nan_float_ = false, uses_nan_double_ = false, uses_zero_float_ = false, uses_zero_double_ = false;
  int loops_ = 0, branches_ = 0, reads_ = 0;
  analysis::SpmdFacts facts_;
  analysis::VarSet truth_;              // SPMD: registers held as masks (truth_registers)
  std::vector<analysis::VarSet> keep_;  // SPMD: per masked statement around, what a write keeps
  std::vector<LoopExit> exits_;         // how each loop around is left
  bool taps_inside_ = false;            // SPMD: writing the body for taps inside their tables
};

}  // namespace sh::opencl
