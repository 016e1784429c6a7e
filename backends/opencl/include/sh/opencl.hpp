#pragma once
// The OpenCL backend: the optimised IR becomes readable OpenCL C 1.2, built
// and run through the ICD loader on any OpenCL device; PoCL on the CPU is
// the default.  A work-item runs one stream element, or on a CPU device
// `lanes` consecutive elements in vector registers (SPMD, as the cpu
// backend's lanes), which the device's compiler turns into SIMD code.  Its library registers
// it as "opencl" when linked (sh::sh); this header is its own API.
//
// Device choice: opencl::Options::device (the setting "device") or the
// environment variable SH_OPENCL_DEVICE, as "P:D" (platform and device
// indices) or a piece of the device's name; otherwise the first device of
// the first platform.
// kernel_for(p, backend("opencl"))->listing() gives the OpenCL C.
// OpenCL kernels cannot call back into the host: they read tables from
// device memory only (no TableSource).
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "sh/backend.hpp"
#include "sh/options.hpp"

namespace sh::opencl {

// Streams on a device that shares host memory are used in place (Auto);
// elsewhere, or always with Copied, they are copied in pieces overlapped
// with the kernel.
enum class Streams { Auto, Copied };

struct Options {
  static constexpr const char* backend_name = "opencl";
  std::string device;  // "P:D" or a piece of a device's name; empty: the default
  int lanes = 0;       // elements per work-item: 1, 2, 4, 8 or 16; 0 chooses from the device
  Streams streams = Streams::Auto;
  // String form: device, lanes (scalar, 2, 4, 8, 16 or auto), streams (auto or copied).
  Settings settings() const;
  void set(const std::string& name, const std::string& value);
};

// Every platform and device found, one line each ("P:D name (platform)").
std::vector<std::string> devices();

// RunStats::details of an opencl run (stats.details_as<opencl::RunDetails>()):
// the bytes a run moved between host and device, and those it did not have
// to.  Streams on a device that shares host memory are used in place;
// elsewhere they are copied both ways, in pieces overlapped with the
// kernel.  Tables stay on the device between runs until their contents
// change, or the table goes, or no kernel's last run read them.
class RunDetails : public sh::RunDetails {
 public:
  std::size_t runs = 0;
  std::size_t to_device = 0;    // streams, changed tables, accumulators, the status
  std::size_t from_device = 0;  // outputs, accumulators, the status
  std::size_t in_place = 0;     // streams the kernel read or wrote in host memory
  std::size_t tables_kept = 0;  // table bytes already on the device from an earlier run
  std::size_t tables_held = 0;  // table bytes the device holds after the last run, for every kernel

  std::unique_ptr<sh::RunDetails> clone() const override;
  void add(const sh::RunDetails& more) override;
  std::vector<std::string> describe() const override;
};

}  // namespace sh::opencl
