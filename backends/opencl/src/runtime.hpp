#pragma once
// The OpenCL host side: finding platforms and devices, one context and
// queue per device, building programs (with the build log and the source
// lines it complains about in every error), and checked calls.
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace sh::opencl {

// Throws sh::Error naming `what` and OpenCL's error code when err != CL_SUCCESS.
void check(cl_int err, const std::string& what);
const char* error_name(cl_int err);

// Releases an OpenCL buffer when it goes out of scope.
struct Buffer {
  cl_mem mem = nullptr;
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer(Buffer&& o) noexcept : mem(o.mem) { o.mem = nullptr; }
  Buffer& operator=(Buffer&& o) noexcept {
    std::swap(mem, o.mem);
    return *this;
  }
  ~Buffer() {
    if (mem) clReleaseMemObject(mem);
  }
};

struct Device {
  cl_platform_id platform = nullptr;
  cl_device_id id = nullptr;
  std::string name, platform_name;
  bool fp64 = false;
  bool unified = false;  // shares the host's memory (a CPU device such as PoCL's)
  bool cpu = false;
  cl_ulong max_alloc = 0;
  cl_ulong global_memory = 0;
  cl_uint compute_units = 0;
  std::size_t max_group = 0;  // work-items in a group
  cl_uint float_lanes = 1;    // the preferred float vector width
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;       // kernels
  cl_command_queue copy_queue = nullptr;  // copies of streams in pieces, beside the kernels
};

// One T for each device opened, made from `args` the first time, never
// destroyed: devices stay open, and kernels use theirs in static
// destructors too.  The set is T's alone, whatever arguments make one.
template <class T>
struct PerDevice {
  std::mutex mutex;
  std::map<cl_device_id, T> of;
  static PerDevice& set() {
    static auto* each = new PerDevice;
    return *each;
  }
};
template <class T, class... Args>
T& one_per_device(const Device& device, Args&&... args) {
  PerDevice<T>& each = PerDevice<T>::set();
  std::lock_guard lock(each.mutex);
  return each.of.try_emplace(device.id, std::forward<Args>(args)...).first->second;
}

// The device `choice` names ("P:D", a piece of a name, or empty for
// SH_OPENCL_DEVICE or else the first device), with its context and queue.
std::shared_ptr<Device> open_device(const std::string& choice);
std::vector<std::string> list_devices();
// Why there is no device: none installed (how to install PoCL), or
// platforms installed whose devices cannot be listed (which, and why).
std::string no_device_found();

// Builds `source` for the device; a failure throws sh::Error with the
// program name, the build log and the source lines the log points at.
cl_program build(const Device& device, const std::string& program_name, const std::string& source,
                 const std::string& options);

}  // namespace sh::opencl
