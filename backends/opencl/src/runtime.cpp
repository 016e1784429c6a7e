#include "runtime.hpp"

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>

#include "sh/error.hpp"

namespace sh::opencl {
namespace {

const char kInstallHint[] =
    "no OpenCL platform or device was found; install PoCL for the CPU (apt-get install pocl-opencl-icd) "
    "or your GPU's OpenCL driver";

std::string info_string(cl_device_id d, cl_device_info what) {
  std::size_t size = 0;
  clGetDeviceInfo(d, what, 0, nullptr, &size);
  std::string s(size, '\0');
  clGetDeviceInfo(d, what, size, s.data(), nullptr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::string platform_name(cl_platform_id p) {
  std::size_t size = 0;
  clGetPlatformInfo(p, CL_PLATFORM_NAME, 0, nullptr, &size);
  std::string s(size, '\0');
  clGetPlatformInfo(p, CL_PLATFORM_NAME, size, s.data(), nullptr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

struct Found {
  cl_platform_id platform;
  cl_device_id device;
  int p, d;
};

std::vector<cl_platform_id> platforms() {
  cl_uint np = 0;
  if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) return {};
  std::vector<cl_platform_id> out(np);
  clGetPlatformIDs(np, out.data(), nullptr);
  return out;
}

// Platforms there are whose devices cannot be listed: installed, but not
// working (PoCL lists none where it cannot use its cache directory).
std::vector<std::string> platforms_without_devices() {
  std::vector<std::string> out;
  for (cl_platform_id p : platforms()) {
    cl_uint nd = 0;
    if (cl_int err = clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &nd); err != CL_SUCCESS || nd == 0)
      out.push_back("'" + platform_name(p) + "' (" + error_name(err) + ")");
  }
  return out;
}

std::vector<Found> all_devices() {
  std::vector<cl_platform_id> all = platforms();
  std::vector<Found> out;
  for (std::size_t p = 0; p < all.size(); ++p) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(all[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS) continue;
    std::vector<cl_device_id> ids(nd);
    clGetDeviceIDs(all[p], CL_DEVICE_TYPE_ALL, nd, ids.data(), nullptr);
    for (cl_uint d = 0; d < nd; ++d) out.push_back({all[p], ids[d], static_cast<int>(p), static_cast<int>(d)});
  }
  return out;
}

template <class T>
T info(cl_device_id d, cl_device_info what) {
  T value{};
  clGetDeviceInfo(d, what, sizeof value, &value, nullptr);
  return value;
}

// What code generation and the launch ask of a device, read once.
void read_capabilities(cl_device_id id, Device& d) {
  d.fp64 = info<cl_device_fp_config>(id, CL_DEVICE_DOUBLE_FP_CONFIG) != 0;
  d.max_alloc = info<cl_ulong>(id, CL_DEVICE_MAX_MEM_ALLOC_SIZE);
  d.global_memory = info<cl_ulong>(id, CL_DEVICE_GLOBAL_MEM_SIZE);
  d.unified = info<cl_bool>(id, CL_DEVICE_HOST_UNIFIED_MEMORY) == CL_TRUE;
  d.cpu = (info<cl_device_type>(id, CL_DEVICE_TYPE) & CL_DEVICE_TYPE_CPU) != 0;
  d.compute_units = info<cl_uint>(id, CL_DEVICE_MAX_COMPUTE_UNITS);
  d.max_group = info<std::size_t>(id, CL_DEVICE_MAX_WORK_GROUP_SIZE);
  d.float_lanes = info<cl_uint>(id, CL_DEVICE_PREFERRED_VECTOR_WIDTH_FLOAT);
}

std::string capabilities(const Device& d) {
  return std::string(d.cpu ? "CPU" : "not a CPU") + ", " + std::to_string(d.compute_units) + " compute units, groups up to " +
         std::to_string(d.max_group) + ", float vectors of " + std::to_string(d.float_lanes) + ", f64 " +
         (d.fp64 ? "yes" : "no") + ", host memory " +
         (d.unified ? "shared" : "separate") + ", largest buffer " + std::to_string(d.max_alloc >> 20) + " MiB";
}

Found choose(const std::vector<Found>& found, std::string choice) {
  if (found.empty()) throw Error(no_device_found());
  if (choice.empty())
    if (const char* env = std::getenv("SH_OPENCL_DEVICE")) choice = env;
  if (choice.empty()) return found.front();
  std::smatch m;
  // Indices of up to 9 digits: a longer one names no device (and would not
  // fit an int).
  if (std::regex_match(choice, m, std::regex(R"((\d{1,9}):(\d{1,9}))"))) {
    for (const Found& f : found)
      if (f.p == std::stoi(m[1]) && f.d == std::stoi(m[2])) return f;
  } else {
    for (const Found& f : found)
      if (info_string(f.device, CL_DEVICE_NAME).find(choice) != std::string::npos) return f;
  }
  std::string known;
  for (const std::string& line : list_devices()) known += "\n  " + line;
  throw Error("no OpenCL device matches '" + choice + "'; found:" + known);
}

}  // namespace

const char* error_name(cl_int err) {
  switch (err) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_ARG_VALUE: return "CL_INVALID_ARG_VALUE";
    default: return "OpenCL error";
  }
}

void check(cl_int err, const std::string& what) {
  if (err == CL_SUCCESS) return;
  std::string hint;
  if (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_RESOURCES || err == CL_OUT_OF_HOST_MEMORY)
    hint = " (the device is out of memory: use a smaller stream, or a device with more memory)";
  throw Error(what + ": " + error_name(err) + " (" + std::to_string(err) + ")" + hint);
}

std::string no_device_found() {
  std::vector<std::string> broken = platforms_without_devices();
  if (broken.empty()) return kInstallHint;
  std::string names;
  for (const std::string& b : broken) names += (names.empty() ? "" : ", ") + b;
  return "OpenCL platforms were found, but none lists a device: " + names +
         "; PoCL lists none where it cannot use its cache directory (POCL_CACHE_DIR) or its compiler";
}

std::vector<std::string> list_devices() {
  std::vector<std::string> lines;
  for (const Found& f : all_devices()) {
    Device d;
    read_capabilities(f.device, d);
    lines.push_back(std::to_string(f.p) + ":" + std::to_string(f.d) + " " + info_string(f.device, CL_DEVICE_NAME) + " (" +
                    platform_name(f.platform) + ", " + info_string(f.device, CL_DEVICE_VERSION) + "): " + capabilities(d));
  }
  return lines;
}

std::shared_ptr<Device> open_device(const std::string& choice) {
  static std::mutex mutex;
  static std::map<cl_device_id, std::shared_ptr<Device>> open;
  std::lock_guard<std::mutex> lock(mutex);
  Found f = choose(all_devices(), choice);
  auto it = open.find(f.device);
  if (it != open.end()) return it->second;
  auto d = std::make_shared<Device>();
  d->platform = f.platform;
  d->id = f.device;
  d->name = info_string(f.device, CL_DEVICE_NAME);
  d->platform_name = platform_name(f.platform);
  read_capabilities(f.device, *d);
  cl_int err = CL_SUCCESS;
  d->context = clCreateContext(nullptr, 1, &f.device, nullptr, nullptr, &err);
  check(err, "creating an OpenCL context on " + d->name);
  try {
    d->queue = clCreateCommandQueue(d->context, f.device, 0, &err);
    check(err, "creating an OpenCL queue on " + d->name);
    d->copy_queue = clCreateCommandQueue(d->context, f.device, 0, &err);
    check(err, "creating an OpenCL copy queue on " + d->name);
  } catch (...) {
    // An open device lives as long as the process; one that failed to open
    // gives back what it took.
    if (d->queue) clReleaseCommandQueue(d->queue);
    clReleaseContext(d->context);
    throw;
  }
  open.emplace(f.device, d);
  return d;
}

cl_program build(const Device& device, const std::string& program_name, const std::string& source,
                 const std::string& options) {
  const char* text = source.c_str();
  std::size_t length = source.size();
  cl_int err = CL_SUCCESS;
  cl_program program = clCreateProgramWithSource(device.context, 1, &text, &length, &err);
  check(err, "program '" + program_name + "': creating the OpenCL program");
  err = clBuildProgram(program, 1, &device.id, options.c_str(), nullptr, nullptr);
  if (err == CL_SUCCESS) return program;

  std::size_t size = 0;
  clGetProgramBuildInfo(program, device.id, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
  std::string log(size, '\0');
  clGetProgramBuildInfo(program, device.id, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
  clReleaseProgram(program);
  log.resize(std::strlen(log.c_str()));  // the log ends in a NUL that would cut the message
  // Compilers name lines as "<source>:12:5:" or "input.cl:12:"; quote them.
  std::vector<std::string> lines;
  std::istringstream in(source);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::set<int> cited;
  std::regex where(R"(:(\d{1,9}):\d+:)");  // a longer number is no line of ours
  for (auto it = std::sregex_iterator(log.begin(), log.end(), where); it != std::sregex_iterator(); ++it)
    cited.insert(std::stoi((*it)[1]));
  std::string quoted;
  for (int n : cited)
    if (n >= 1 && n <= static_cast<int>(lines.size())) quoted += "\n  line " + std::to_string(n) + ": " + lines[n - 1];
  throw Error("program '" + program_name + "': OpenCL build failed on " + device.name + " (" + error_name(err) +
              ")\nbuild log:\n" + log + (quoted.empty() ? "" : "\nsource:" + quoted));
}

}  // namespace sh::opencl
