#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

#include "codegen.hpp"
#include "device_tables.hpp"
#include "runtime.hpp"
#include "stream_buffers.hpp"
#include "sh/detail/sums.hpp"
#include "sh/error.hpp"
#include "sh/ir/printer.hpp"
#include "sh/opencl.hpp"

namespace sh::opencl {
namespace {

// -w: the source is generated, and its compiler's warnings (a truth value
// or-ed with a constant the program wrote) are not the user's to act on;
// PoCL printed their count on stderr.
std::string build_options(const sh::Options& o) {
  if (o.math == MathMode::Fast) return "-w -cl-fast-relaxed-math";
  return "-w -cl-fp32-correctly-rounded-divide-sqrt";
}

// Elements per work-item: the setting, or on a CPU device its preferred
// float vector width, up to 16 (one on other devices, whose compilers
// spread work-items over SIMD lanes themselves).
int lanes_for(const sh::Options& o, const Device& d) {
  int chosen = o.get<Options>().lanes;
  if (chosen != 0 && chosen != 1 && chosen != 2 && chosen != 4 && chosen != 8 && chosen != 16)
    throw Error("opencl backend: lanes is " + std::to_string(chosen) + "; expected 1, 2, 4, 8, 16 or 0 (auto)");
  if (chosen != 0) return chosen;
  if (!d.cpu) return 1;
  int lanes = 1;
  while (lanes * 2 <= static_cast<int>(d.float_lanes) && lanes * 2 <= 16) lanes *= 2;
  return lanes;
}

class OpenClKernel : public Kernel {
 public:
  OpenClKernel(const ir::Program& p, const sh::Options& o)
      : program_(p), options_(o), device_(open_device(o.get<Options>().device)), lanes_(lanes_for(o, *device_)) {
    Source source = generate(p, o, lanes_, device_->max_alloc);
    source_ = std::move(source.text);
    if (source.needs_fp64 && !device_->fp64)
      throw Error("program '" + p.name + "': needs double precision (f64), which OpenCL device '" + device_->name +
                  "' lacks (no cl_khr_fp64); use precision f32 and float values, or another device");
    cl_program_ = build(*device_, p.name, source_, build_options(o));
    table_slots_.assign(p.tables.size(), kNoTable);
    try {
      one_ = make_kernel(kKernelName, 1);
      if (lanes_ > 1) many_ = make_kernel(kLanesKernelName, lanes_);
    } catch (...) {
      release();  // a constructor that throws runs no destructor
      throw;
    }
  }

  ~OpenClKernel() override { release(); }

  void run(const RunArgs& args, RunStats& stats) override {
    std::lock_guard<std::mutex> lock(mutex_);
    auto moved = std::make_shared<RunDetails>();
    moved->runs = 1;
    std::vector<Buffer> buffers;
    buffers.reserve(args.inputs.size() + args.outputs.size() + args.tables.size() + 1);
    Borrowed borrowed(stream_buffers_on(*device_));  // copied streams' buffers
    cl_uint arg = 0;
    cl_long base = 0;
    set(arg++, sizeof base, &base);
    const LaunchDomain& d = args.domain;
    cl_long domain[3] = {static_cast<cl_long>(d.first), d.extent[0] ? static_cast<cl_long>(d.extent[0]) : CL_LONG_MAX,
                         static_cast<cl_long>(d.extent[1])};
    for (cl_long& k : domain) set(arg++, sizeof k, &k);
    // On a device that shares host memory the streams are used in place;
    // elsewhere (or with the setting streams=copied) they are copied, in
    // pieces overlapped with the kernel (run_in_pieces).  An output that is
    // also an input (an in-out channel) is copied, since buffers over one
    // host region may not overlap.
    const bool copied = copies_streams();
    std::vector<cl_mem> streams;  // inputs, then outputs
    for (const BufferView& b : args.inputs) {
      std::size_t size = bytes(b.type, b.count);
      if (copied) {
        streams.push_back(borrow(borrowed, size, CL_MEM_READ_ONLY, "an input"));
        set(arg++, sizeof(cl_mem), &streams.back());
        continue;  // counted piece by piece
      }
      moved->in_place += size;
      set_buffer(arg++, buffers, make(size, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, b.data, "an input"));
      streams.push_back(buffers.back().mem);
    }
    std::vector<bool> in_place;
    for (const BufferView& b : args.outputs) {
      bool shared = std::any_of(args.inputs.begin(), args.inputs.end(), [&](const BufferView& in) { return in.data == b.data; });
      in_place.push_back(!copied && !shared);
      std::size_t size = bytes(b.type, b.count);
      if (copied) {
        streams.push_back(borrow(borrowed, size, CL_MEM_WRITE_ONLY, "an output"));
        set(arg++, sizeof(cl_mem), &streams.back());
        continue;
      }
      set_buffer(arg++, buffers,
                 make(size, CL_MEM_WRITE_ONLY | (in_place.back() ? CL_MEM_USE_HOST_PTR : 0), in_place.back() ? b.data : nullptr,
                      "an output"));
      streams.push_back(buffers.back().mem);
    }
    for (std::size_t u = 0; u < args.uniforms.size(); ++u) set_uniform(arg, program_.uniforms[u], args.uniforms[u]);
    // An accumulator's adds are summed on the device from zero and added
    // into the host's sums after the run: runs on other threads may add to
    // the same sums meanwhile.
    std::vector<std::pair<const TableView*, cl_mem>> sums;
    std::vector<std::vector<char>> added;
    std::vector<std::shared_ptr<const Buffer>> tables;  // held by this run, whatever other runs keep
    for (const TableView& t : args.tables) {
      if (t.sums) {
        added.emplace_back(t.bytes(), 0);  // zero bits: 0 in f32 and in i32
        set_buffer(arg++, buffers,
                   make(t.bytes(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, added.back().data(), "an accumulator"));
        sums.emplace_back(&t, buffers.back().mem);
        moved->to_device += t.bytes();
        moved->from_device += t.bytes();
      } else {
        tables.push_back(table_copy(static_cast<std::size_t>(&t - args.tables.data()), t, *moved));
        set(arg++, sizeof(cl_mem), &tables.back()->mem);
      }
      for (int d = 0; d < 3; ++d) set(arg++, sizeof(cl_int), &t.dims[d]);
    }
    cl_long status[3] = {0, 0, 0};  // the loop past its cap, its element, the claim to report them
    set_buffer(arg++, buffers, make(sizeof status, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, status, "the status"));
    moved->to_device += sizeof status;
    moved->from_device += sizeof status;

    try {
      if (copied) {
        run_in_pieces(args, streams, sums.empty(), *moved);
      } else {
        launch(args.count, sums.empty());
        take_outputs(args, streams, in_place, *moved);
      }
      for (std::size_t k = 0; k < sums.size(); ++k)
        check(clEnqueueReadBuffer(device_->queue, sums[k].second, CL_FALSE, 0, sums[k].first->bytes(), added[k].data(),
                                  0, nullptr, nullptr),
              where("reading an accumulator"));
      check(clEnqueueReadBuffer(device_->queue, buffers.back().mem, CL_TRUE, 0, sizeof status, status, 0, nullptr, nullptr),
            where("finishing the run"));
    } catch (...) {
      // Kernels and reads already enqueued write the caller's memory: none
      // may once the run has returned.
      clFinish(device_->queue);
      throw;
    }
    if (status[0] != 0) throw runaway(status[0], static_cast<cl_long>(args.element(static_cast<std::size_t>(status[1]))));
    for (std::size_t k = 0; k < sums.size(); ++k)  // each add atomic: runs on other threads add too
      detail::add_sums_from(sums[k].first->element.scalar, sums[k].first->sums, added[k].data(), added[k].size());
    moved->tables_held = tables_on(*device_).bytes();
    stats.details = std::move(moved);
  }

  std::string listing() const override { return source_; }

 private:
  void release() {
    // Only where a slot names a table: the device's set exists then, and
    // nothing is allocated in a destructor.
    if (std::any_of(table_slots_.begin(), table_slots_.end(), [](const TableKey& k) { return k != kNoTable; }))
      tables_on(*device_).release(table_slots_);
    for (const Launcher* k : {&one_, &many_})
      if (k->kernel) clReleaseKernel(k->kernel);
    if (cl_program_) clReleaseProgram(cl_program_);
  }

  // A kernel and the work-items of its whole work-groups.
  struct Launcher {
    cl_kernel kernel = nullptr;
    std::size_t group = 0;  // 0: none chosen, groups of one
  };

  Launcher make_kernel(const char* name, int lanes) {
    cl_int err = CL_SUCCESS;
    Launcher l;
    l.kernel = clCreateKernel(cl_program_, name, &err);
    check(err, "program '" + program_.name + "': creating the OpenCL kernel " + name);
    l.group = group_size(l.kernel, array_bytes(program_) * static_cast<std::size_t>(lanes));
    return l;
  }

  // The bytes of a work-item's local arrays, per element it runs.
  static std::size_t array_bytes(const ir::Program& p) {
    std::size_t bytes = 0;
    for (const ir::Var& v : p.vars)
      if (v.kind == ir::VarKind::Array) bytes += static_cast<std::size_t>(v.length) * ir::element_bytes(v.type);
    return bytes;
  }

  // Outputs of a run whose streams were not copied in pieces: read back an
  // output that is also an input; map the others, used in place.
  void take_outputs(const RunArgs& args, const std::vector<cl_mem>& streams, const std::vector<bool>& in_place,
                    RunDetails& moved) {
    for (std::size_t o = 0; o < args.outputs.size(); ++o) {
      std::size_t size = bytes(args.outputs[o].type, args.outputs[o].count);
      cl_mem mem = streams[args.inputs.size() + o];
      if (size == 0) continue;  // nothing to read, and no memory to read it into
      if (!in_place[o]) {
        check(clEnqueueReadBuffer(device_->queue, mem, CL_FALSE, 0, size, args.outputs[o].data, 0, nullptr, nullptr),
              where("reading an output"));
        moved.from_device += size;
        continue;
      }
      // Mapping makes the host memory current (a copy only where the
      // implementation kept its own).
      cl_int err = CL_SUCCESS;
      void* mapped = clEnqueueMapBuffer(device_->queue, mem, CL_TRUE, CL_MAP_READ, 0, size, 0, nullptr, nullptr, &err);
      check(err, where("mapping an output"));
      bool kept_apart = mapped != args.outputs[o].data;
      if (kept_apart) std::memcpy(args.outputs[o].data, mapped, size);
      (kept_apart ? moved.from_device : moved.in_place) += size;
      check(clEnqueueUnmapMemObject(device_->queue, mem, mapped, 0, nullptr, nullptr), where("unmapping an output"));
    }
  }

  bool copies_streams() const { return !device_->unified || options_.get<Options>().streams == Streams::Copied; }

  // Copied streams go in pieces: each piece's inputs are written on the
  // copy queue while the kernel runs the piece before on the compute
  // queue, and its outputs are read back while the kernel runs the piece
  // after, so that a device which copies (a GPU) moves data and computes
  // at once.  Streams too short to gain go in one piece.  Pieces do not
  // rerun the elements before them (launch's whole last group), which
  // would write outputs a read may be taking.
  void run_in_pieces(const RunArgs& args, const std::vector<cl_mem>& streams, bool may_repeat, RunDetails& moved) {
    if (args.count == 0) return;
    const std::size_t span = static_cast<std::size_t>(lanes_) * std::max<std::size_t>((lanes_ > 1 ? many_ : one_).group, 1);
    std::size_t piece = std::max(kPieceElements / span, std::size_t{1}) * span;
    std::size_t pieces = args.count <= piece ? 1 : std::min<std::size_t>(kMostPieces, (args.count + piece - 1) / piece);
    piece = pieces == 1 ? args.count : ((args.count + pieces - 1) / pieces + span - 1) / span * span;
    pieces = (args.count + piece - 1) / std::max<std::size_t>(piece, 1);  // every piece holds elements
    // Released however the run ends; on an error, only once both queues
    // are done with the host memory they were given.
    struct Events {
      Events(const Device& d, std::size_t pieces) : queues{d.queue, d.copy_queue}, written(pieces), ran(pieces) {}
      Events(const Events&) = delete;
      Events& operator=(const Events&) = delete;
      ~Events() {
        for (cl_command_queue q : queues) clFinish(q);
        for (std::vector<cl_event>* events : {&written, &ran, &read})
          for (cl_event e : *events)
            if (e) clReleaseEvent(e);
      }
      cl_command_queue queues[2];
      std::vector<cl_event> written, ran, read;
    } events(*device_, pieces);
    std::vector<cl_event>& written = events.written;
    std::vector<cl_event>& ran = events.ran;
    std::vector<cl_event>& read = events.read;
    auto copy = [&](const BufferView& b, cl_mem mem, std::size_t p, bool in, cl_event* wait, cl_event* done) {
      std::size_t element = bytes(b.type, 1), first = p * piece, count = std::min(piece, args.count - first);
      count = std::min(count, b.count - std::min(first, b.count));
      if (count == 0) return;
      char* host = static_cast<char*>(b.data) + first * element;
      cl_int err = in ? clEnqueueWriteBuffer(device_->copy_queue, mem, CL_FALSE, first * element, count * element, host,
                                             wait ? 1 : 0, wait, done)
                      : clEnqueueReadBuffer(device_->copy_queue, mem, CL_FALSE, first * element, count * element, host,
                                            wait ? 1 : 0, wait, done);
      check(err, where(in ? "writing a piece of an input" : "reading a piece of an output"));
      (in ? moved.to_device : moved.from_device) += count * element;
    };
    auto read_back = [&](std::size_t p) {
      for (std::size_t o = 0; o < args.outputs.size(); ++o) {
        read.emplace_back();
        copy(args.outputs[o], streams[args.inputs.size() + o], p, false, &ran[p], &read.back());
      }
    };
    for (std::size_t p = 0; p < pieces; ++p) {
      for (std::size_t i = 0; i < args.inputs.size(); ++i) copy(args.inputs[i], streams[i], p, true, nullptr, nullptr);
      check(clEnqueueMarkerWithWaitList(device_->copy_queue, 0, nullptr, &written[p]), where("marking a piece's writes"));
      std::size_t first = p * piece, count = std::min(piece, args.count - first);
      launch(count, may_repeat && pieces == 1, first, &written[p]);
      check(clEnqueueMarkerWithWaitList(device_->queue, 0, nullptr, &ran[p]), where("marking a piece's run"));
      if (p > 0) read_back(p - 1);
    }
    read_back(pieces - 1);
    check(clFinish(device_->copy_queue), where("finishing the copies"));
  }

  // Whole work-groups of one size chosen for the kernel, so that the device
  // compiles one work-group function and vectorises it unmasked; the last
  // partial group runs as one more whole group ending at the stream's end
  // (its first elements run twice, giving the same values), which a program
  // that adds into accumulators must not do.  Elements left over (all of a
  // short stream, and an accumulating program's after its whole
  // work-items) run in the one-element kernel.  No launch leaves the group
  // size to the implementation: PoCL lays a group's private memory on one
  // thread's stack, and the thousands of work-items it chose for a light
  // pass overflowed it.
  void launch(std::size_t count, bool may_repeat, std::size_t start = 0, const cl_event* wait = nullptr) {
    const Launcher& k = lanes_ > 1 ? many_ : one_;
    std::size_t lanes = static_cast<std::size_t>(lanes_), span = k.group * lanes;
    if (may_repeat && span != 0 && count >= span) {
      std::size_t full = count / span * span;
      enqueue(k, start, full / lanes, k.group, wait);
      if (full != count) enqueue(k, start + count - span, k.group, k.group, wait);
      return;
    }
    std::size_t items = lanes > 1 ? count / lanes : 0;
    if (items != 0) enqueue_in_groups(many_, lanes, start, items, wait);
    if (items * lanes != count) enqueue_in_groups(one_, 1, start + items * lanes, count - items * lanes, wait);
  }

  // Work-items of `lanes` elements each from `base`: whole groups of the
  // kernel's size, then the rest in groups of one.
  void enqueue_in_groups(const Launcher& k, std::size_t lanes, std::size_t base, std::size_t work_items,
                         const cl_event* wait) {
    std::size_t group = std::max<std::size_t>(k.group, 1), whole = work_items / group * group;
    if (whole != 0) enqueue(k, base, whole, group, wait);
    if (whole != work_items) enqueue(k, base + whole * lanes, work_items - whole, 1, wait);
  }

  void enqueue(const Launcher& k, std::size_t base, std::size_t work_items, std::size_t group, const cl_event* wait) {
    cl_long first = static_cast<cl_long>(base);
    check(clSetKernelArg(k.kernel, 0, sizeof first, &first), where("setting the first element"));
    check(clEnqueueNDRangeKernel(device_->queue, k.kernel, 1, nullptr, &work_items, &group, wait ? 1 : 0, wait, nullptr),
          where("launching the kernel"));
  }

  // The largest multiple of the kernel's preferred group size up to 1024
  // that the kernel allows (0: none, then groups of one), and whose
  // work-items' local arrays (`array_bytes` each) take at most 128 KiB:
  // PoCL lays a group's private memory on one thread's stack, which
  // groups of 256 work-items of 4 KiB each overflowed.
  std::size_t group_size(cl_kernel kernel, std::size_t array_bytes) const {
    constexpr std::size_t kGroupArrayBytes = 128 << 10;
    std::size_t most = 0, multiple = 0;
    clGetKernelWorkGroupInfo(kernel, device_->id, CL_KERNEL_WORK_GROUP_SIZE, sizeof most, &most, nullptr);
    clGetKernelWorkGroupInfo(kernel, device_->id, CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE, sizeof multiple,
                             &multiple, nullptr);
    if (multiple == 0) return 0;
    std::size_t fits = std::min<std::size_t>({most, 1024, kGroupArrayBytes / std::max<std::size_t>(array_bytes, 1)});
    return fits >= multiple ? fits / multiple * multiple : std::max<std::size_t>(fits, 1);
  }

  std::string where(const std::string& what) const {
    return "program '" + program_.name + "' on OpenCL device '" + device_->name + "': " + what;
  }

  static std::size_t bytes(ir::Type t, std::size_t count) { return count * t.width * ir::storage_bytes(t.scalar); }

  Buffer make(std::size_t size, cl_mem_flags flags, void* host, const char* what) {
    if (size > device_->max_alloc)
      throw Error(where(std::string(what) + " needs " + std::to_string(size) + " bytes, more than the device's largest buffer (" +
                        std::to_string(device_->max_alloc) + " bytes); split the stream"));
    Buffer b;
    cl_int err = CL_SUCCESS;
    // OpenCL has no empty buffers: an empty one is a byte that is never read.
    if (size == 0) flags &= ~static_cast<cl_mem_flags>(CL_MEM_COPY_HOST_PTR | CL_MEM_USE_HOST_PTR);
    b.mem = clCreateBuffer(device_->context, flags, size == 0 ? 1 : size, size == 0 ? nullptr : host, &err);
    check(err, where(std::string("allocating ") + what + " of " + std::to_string(size) + " bytes"));
    return b;
  }

  // A copied stream's device buffer, one used before where the device has
  // one idle (stream_buffers.hpp).
  cl_mem borrow(Borrowed& borrowed, std::size_t size, cl_mem_flags flags, const char* what) {
    return borrowed.take(size, flags, [&] { return make(size, flags, nullptr, what); });
  }

  // Tables stay on the device between runs until their version changes,
  // one copy of each for every kernel (device_tables.hpp): a run with
  // another table in a slot (the same kernel for another scene) lets the
  // last one go.
  std::shared_ptr<const Buffer> table_copy(std::size_t slot, const TableView& t, RunDetails& moved) {
    if (!t.data)  // a TableSource's elements come as a kernel asks for them, which an OpenCL kernel cannot
      throw Error(where("table '" + program_.tables.at(slot).name +
                        "' is read through a TableSource (its elements are not in memory): OpenCL kernels read "
                        "whole tables; use a backend that reads through sources (cpu, interp)"));
    DeviceTables::Copy copy = tables_on(*device_).hold(table_slots_, slot, t, [&] {
      return make(t.bytes(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, const_cast<void*>(t.data), "a table");
    });
    (copy.made ? moved.to_device : moved.tables_kept) += t.bytes();
    return copy.buffer;
  }

  // Both kernels take the same arguments.
  void set(cl_uint index, std::size_t size, const void* value) {
    for (const Launcher* k : {&one_, &many_})
      if (k->kernel) check(clSetKernelArg(k->kernel, index, size, value), where("setting argument " + std::to_string(index)));
  }

  void set_buffer(cl_uint index, std::vector<Buffer>& keep, Buffer b) {
    set(index, sizeof(cl_mem), &b.mem);
    keep.push_back(std::move(b));
  }

  // Uniform components are scalar arguments in the register type.
  void set_uniform(cl_uint& arg, ir::VarId var, const std::array<double, 4>& value) {
    ir::Type t = program_.type_of(var);
    for (int c = 0; c < t.width; ++c) {
      if (t.scalar == ir::Scalar::I32 || t.scalar == ir::Scalar::Bool) {
        cl_int v = static_cast<cl_int>(value[c]);
        set(arg++, sizeof v, &v);
      } else if (t.scalar == ir::Scalar::F64 || options_.precision == Precision::F64) {
        cl_double v = value[c];
        set(arg++, sizeof v, &v);
      } else {
        cl_float v = static_cast<cl_float>(value[c]);
        set(arg++, sizeof v, &v);
      }
    }
  }

  Error runaway(cl_long loop, cl_long element) const {
    int n = 0;
    const ir::Stmt* which = nullptr;
    find_loop(program_.body, loop, n, which);
    return runaway_loop(program_, *which, static_cast<std::uint64_t>(element), options_.max_loop_iterations);
  }

  // Loops are numbered in the order the generator meets them: a loop that
  // tests last writes its test (the header) after its body and update.
  void find_loop(const ir::Block& b, cl_long wanted, int& n, const ir::Stmt*& out) const {
    for (const ir::Stmt& s : b) {
      if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        if (++n == wanted) out = &s;
        if (l->test_at_top) find_loop(l->header, wanted, n, out);
        find_loop(l->body, wanted, n, out);
        find_loop(l->update, wanted, n, out);
        if (!l->test_at_top) find_loop(l->header, wanted, n, out);
      } else if (auto* i = std::get_if<ir::If>(&s.node)) {
        find_loop(i->then_body, wanted, n, out);
        find_loop(i->else_body, wanted, n, out);
      }
    }
  }

  ir::Program program_;
  sh::Options options_;
  std::shared_ptr<Device> device_;
  TableSlots table_slots_;  // the table each of the program's last read here
  std::string source_;
  int lanes_;  // elements per work-item of many_
  cl_program cl_program_ = nullptr;
  Launcher one_, many_;  // one element per work-item; lanes_ (above 1) per work-item
  std::mutex mutex_;
  static constexpr std::size_t kPieceElements = std::size_t{1} << 18, kMostPieces = 8;
};

class OpenClBackend : public Backend {
 public:
  std::string name() const override { return "opencl"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const sh::Options& o) override {
    return std::make_unique<OpenClKernel>(p, o);
  }
  std::vector<Setting> settings() const override {
    return {{"device", "P:D (platform and device indices) or a piece of a device's name (shtrace info lists them)"},
            {"lanes",
             "scalar, 2, 4, 8, 16 or auto: elements per work-item; auto: the device's float vector width on a CPU (at most "
             "16), 1 elsewhere"},
            {"streams",
             "auto or copied: auto uses streams in place on a device that shares host memory; copied (always on other "
             "devices) copies them in pieces overlapped with the kernel"}};
  }
  BackendOptions default_options() const override { return Options{}; }
  std::vector<Variant> variants() const override {
    return {{"scalar", Options{.device = {}, .lanes = 1}}, {"w8", Options{.device = {}, .lanes = 8}}};
  }
  int lanes(const sh::Options& o) const override { return lanes_for(o, *open_device(o.get<Options>().device)); }
  std::string environment_key(const sh::Options& o) const override {
    if (!o.get<Options>().device.empty()) return {};  // the options name it
    const char* chosen = std::getenv("SH_OPENCL_DEVICE");
    return chosen ? chosen : "";
  }
  std::vector<std::string> describe() const override {
    std::vector<std::string> lines;
    for (const std::string& d : list_devices()) lines.push_back("opencl: " + d);
    if (lines.empty()) lines.push_back("opencl: " + no_device_found());
    return lines;
  }
};

// Registered as the library loads: linking it is enough.
const bool registered = (sh::register_backend("opencl", [] { return std::make_unique<OpenClBackend>(); }), true);

}  // namespace

std::vector<std::string> devices() { return list_devices(); }

}  // namespace sh::opencl
