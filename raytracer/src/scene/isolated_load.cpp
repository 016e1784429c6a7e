// A model file is read in a child process under memory and time limits, so
// that a crash, a hang or a runaway allocation inside assimp is an error
// naming the file, not the end of the tracer.
//
// fork without exec, not posix_spawn: the tracer is a library (shtrace, the
// tests and users' programs link it), so there is no loader executable to
// spawn, and re-executing /proc/self/exe works only for shtrace.  The
// process may have threads (oneTBB's workers, Open MPI's progress thread);
// after fork only the forking thread exists in the child, so the child
// touches nothing those threads might have held: it reads the file with
// assimp (single-threaded, our code only), allocates with malloc/new (glibc
// resets malloc's locks across fork), writes the triangles to a pipe and
// leaves with _exit (no atexit handlers, no stdio flush, no MPI or TBB
// calls).  Should a lock held at the fork still block the child, the
// wall-clock limit turns that into an error too.
#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <new>

#include "input_file.hpp"
#include "model_reader.hpp"
#include "sh/error.hpp"

namespace sh::rt {
namespace {

// The child's exit codes that carry a meaning of their own.
constexpr int kLoaded = 0;          // the pipe holds the triangles or an error message
constexpr int kOutOfMemory = 3;     // an allocation failed under the memory limit
constexpr int kCannotReport = 4;    // the pipe could not be written

// Limits beyond these are no limit (and keep the arithmetic in range).
constexpr std::size_t kNoMemoryLimitMiB = std::size_t{1} << 40;
constexpr double kLongestSeconds = 1e7;

// The message the child sends: a tag, then the triangles or the error.
enum class Tag : std::uint8_t { triangles = 1, error = 2 };

void put(std::string& out, const void* data, std::size_t bytes) { out.append(static_cast<const char*>(data), bytes); }

void put_count(std::string& out, std::uint64_t n) { put(out, &n, sizeof n); }

void put_vec3s(std::string& out, const std::vector<Vec3>& v) {
  put_count(out, v.size());
  put(out, v.data(), v.size() * sizeof(Vec3));
}

void put_string(std::string& out, const std::string& s) {
  put_count(out, s.size());
  put(out, s.data(), s.size());
}

std::string encode(const Scene& model) {
  std::string out(1, static_cast<char>(Tag::triangles));
  put_vec3s(out, model.mesh.positions);
  put_vec3s(out, model.mesh.normals);
  put_vec3s(out, model.mesh.colors);
  put_count(out, model.warnings.size());
  for (const std::string& w : model.warnings) put_string(out, w);
  return out;
}

std::string encode_error(const std::string& message) {
  std::string out(1, static_cast<char>(Tag::error));
  put_string(out, message);
  return out;
}

// Reads back what encode wrote; any shortfall means the child's message is
// not whole (it cannot happen after a clean exit, but is checked anyway).
class Decoder {
 public:
  Decoder(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}

  Tag tag() {
    std::uint8_t t = 0;
    take(&t, 1);
    return static_cast<Tag>(t);
  }

  std::uint64_t count(std::size_t item_bytes) {
    std::uint64_t n = 0;
    take(&n, sizeof n);
    if (n > (bytes_.size() - at_) / item_bytes) broken();
    return n;
  }

  std::vector<Vec3> vec3s() {
    std::vector<Vec3> v(count(sizeof(Vec3)));
    take(v.data(), v.size() * sizeof(Vec3));
    return v;
  }

  std::string string() {
    std::string s(count(1), '\0');
    take(s.data(), s.size());
    return s;
  }

 private:
  // An empty vector's data() may be null, which memcpy may not be given
  // even for no bytes.
  void take(void* to, std::size_t bytes) {
    if (bytes > bytes_.size() - at_) broken();
    if (bytes == 0) return;
    std::memcpy(to, bytes_.data() + at_, bytes);
    at_ += bytes;
  }
  [[noreturn]] void broken() const { throw Error(path_ + ": the loading process sent back an incomplete answer"); }

  const std::string& bytes_;
  const std::string& path_;
  std::size_t at_ = 0;
};

Scene decode(const std::string& bytes, const std::string& path) {
  Decoder d(bytes, path);
  Tag tag = d.tag();
  if (tag == Tag::error) throw Error(d.string());
  if (tag != Tag::triangles) throw Error(path + ": the loading process sent back an answer of unknown kind");
  Scene model;
  model.mesh.positions = d.vec3s();
  model.mesh.normals = d.vec3s();
  model.mesh.colors = d.vec3s();
  std::size_t triangles = model.mesh.positions.size() / 3;
  if (model.mesh.positions.size() % 3 != 0 || model.mesh.normals.size() != model.mesh.positions.size() ||
      (!model.mesh.colors.empty() && model.mesh.colors.size() != model.mesh.positions.size()))
    throw Error(path + ": the loading process sent back arrays of different lengths");
  model.mesh.material.assign(triangles, 0);
  for (std::uint64_t n = d.count(sizeof(std::uint64_t)); n > 0; --n) model.warnings.push_back(d.string());
  return model;
}

bool write_all(int fd, const std::string& bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

// The address space this process has now, so that the child's limit counts
// only what the load adds (a forked child starts with all of it).
std::size_t address_space_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

[[noreturn]] void out_of_memory() { ::_exit(kOutOfMemory); }

void limit(int resource, rlim_t soft, rlim_t hard) {
  rlimit l{soft, hard};
  ::setrlimit(resource, &l);
}

// The parent's handlers (Open MPI's, a debugger's) are not the child's: a
// fault in the loader must end the child with its signal, which the parent
// reports.
void default_signals() {
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGXCPU, SIGTERM}) std::signal(sig, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
}

[[noreturn]] void child(int fd, const std::string& path, const Transform& t, const LoadLimits& limits,
                        std::size_t address_space) {
  default_signals();
  int null = ::open("/dev/null", O_WRONLY);  // the parent's stdout is not the child's to write
  if (null >= 0) ::dup2(null, STDOUT_FILENO);
  limit(RLIMIT_CORE, 0, 0);
  rlim_t memory = limits.memory_mib >= kNoMemoryLimitMiB ? RLIM_INFINITY : address_space + (limits.memory_mib << 20);
  limit(RLIMIT_AS, memory, memory);
  auto cpu = static_cast<rlim_t>(std::ceil(std::min(limits.seconds, kLongestSeconds)));
  limit(RLIMIT_CPU, cpu, cpu + 1);  // SIGXCPU at the limit, SIGKILL a second later
  std::set_new_handler(out_of_memory);
  std::string answer;
  try {
    if (limits.in_child) limits.in_child();
    answer = encode(read_model_file(path, t));
  } catch (const Error& e) {
    answer = encode_error(e.what());
  } catch (const std::bad_alloc&) {
    out_of_memory();
  } catch (const std::exception& e) {
    answer = encode_error(path + ": cannot load the model: " + e.what());
  }
  ::_exit(write_all(fd, answer) ? kLoaded : kCannotReport);
}

std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

// Reads the child's answer until it closes the pipe or the wall-clock limit
// passes; returns false at the limit.
bool read_answer(int fd, std::chrono::steady_clock::time_point deadline, std::string& answer) {
  char buffer[1 << 16];
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) return false;
    if (ready <= 0) continue;
    ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;  // end of file (or an error: the exit status tells)
    answer.append(buffer, static_cast<std::size_t>(n));
  }
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return status;
}

// Turns how the child ended into the scene or an error naming the cause.
Scene outcome(int status, const std::string& answer, const std::string& path, const LoadLimits& limits) {
  std::string limit_text = " (--load-memory and --load-seconds raise the limits)";
  if (status < 0) throw Error(path + ": lost track of the loading process");
  if (WIFSIGNALED(status)) {
    int sig = WTERMSIG(status);
    if (sig == SIGXCPU)
      throw Error(path + ": the model loader ran past the " + seconds_text(limits.seconds) + " CPU-time limit" + limit_text);
    if (sig == SIGKILL)
      throw Error(path + ": the model loader was killed (signal 9) while loading: the system may have run out of memory" +
                  limit_text);
    throw Error(path + ": the model loader was killed by signal " + std::to_string(sig) + " (" + strsignal(sig) +
                ") while loading: the file is malformed in a way the model library does not catch");
  }
  int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == kOutOfMemory)
    throw Error(path + ": the model loader used more than the " + std::to_string(limits.memory_mib) +
                " MiB memory limit (a count in the file may be wrong)" + limit_text);
  if (code != kLoaded) throw Error(path + ": the model loader failed (exit status " + std::to_string(code) + ")");
  return decode(answer, path);
}

}  // namespace

Scene read_model_isolated(const std::string& path, const Transform& t, const LoadLimits& limits) {
  if (!(limits.seconds > 0) || limits.memory_mib == 0) throw Error(path + ": model load limits must be positive");
  check_input_file(path, "the model file");
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw Error(path + ": cannot make a pipe for the loading process: " + std::strerror(errno));
  std::size_t address_space = address_space_bytes();
  auto deadline = std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::duration<double>(std::min(limits.seconds, kLongestSeconds)));
  pid_t pid = ::fork();
  if (pid < 0) {
    int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(path + ": cannot start the loading process: " + std::strerror(error));
  }
  if (pid == 0) {
    // Only its own pipe stays open: another thread's load's pipe, kept
    // here, would keep that load from seeing its own child finish.
    auto write_end = static_cast<unsigned>(fds[1]);
    if (write_end > 3) ::close_range(3, write_end - 1, 0);
    ::close_range(write_end + 1, ~0U, 0);
    child(fds[1], path, t, limits, address_space);
  }
  ::close(fds[1]);
  std::string answer;
  bool in_time = read_answer(fds[0], deadline, answer);
  ::close(fds[0]);
  if (!in_time) {
    ::kill(pid, SIGKILL);
    wait_for(pid);
    throw Error(path + ": the model loader ran past the " + seconds_text(limits.seconds) +
                " limit (--load-seconds raises it)");
  }
  return outcome(wait_for(pid), answer, path, limits);
}

}  // namespace sh::rt
