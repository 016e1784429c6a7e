#include "output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include <sh/error.hpp>

namespace shtrace {
namespace fs = std::filesystem;

namespace {

constexpr int kMostNumbered = 9999;
// What a temporary's name adds to the name it stands for (".PID.N.tmp").
constexpr std::size_t kTemporarySuffixBytes = 32;

// Holds back the signals that end a process from the terminal or a kill
// while a file is written and moved into place: the process then ends with
// the file in place, not with its temporary left beside it.  A handler
// notes the signal on whichever thread takes it (a backend's worker as
// likely as this one; a mask would hold back only this thread's), and the
// signal is raised again once the file is in place.
constexpr int kHeldSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
volatile std::sig_atomic_t held_signal = 0;

extern "C" void note_signal(int signal) { held_signal = signal; }

class SignalsHeld {
 public:
  SignalsHeld() {
    struct sigaction noting {};
    noting.sa_handler = note_signal;
    sigemptyset(&noting.sa_mask);
    for (std::size_t k = 0; k < std::size(kHeldSignals); ++k) sigaction(kHeldSignals[k], &noting, &before_[k]);
  }
  ~SignalsHeld() {
    for (std::size_t k = 0; k < std::size(kHeldSignals); ++k) sigaction(kHeldSignals[k], &before_[k], nullptr);
    if (int signal = held_signal; signal != 0) {
      held_signal = 0;
      std::raise(signal);
    }
  }
  SignalsHeld(const SignalsHeld&) = delete;
  SignalsHeld& operator=(const SignalsHeld&) = delete;

 private:
  struct sigaction before_[std::size(kHeldSignals)];
};

std::string numbered(const fs::path& first, int n) {
  if (n == 1) return first.string();
  fs::path p = first;
  p.replace_filename(first.stem().string() + "-" + std::to_string(n) + first.extension().string());
  return p.string();
}

// Moves `from` to `to` unless `to` exists; false if it does.  renameat2's
// RENAME_NOREPLACE makes the check and the move one step; a file system
// without it gets the check, then the move.
bool move_unless_taken(const std::string& from, const std::string& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return true;
  if (errno == EEXIST) return false;
  if (errno != EINVAL && errno != ENOSYS) throw sh::Error(to + ": cannot write the image: " + std::strerror(errno));
  if (fs::exists(to)) return false;
  fs::rename(from, to);
  return true;
}

void make_parent(const fs::path& path) {
  std::error_code failed;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), failed);
  if (failed)
    throw sh::Error(path.string() + ": cannot make its directory " + path.parent_path().string() + ": " + failed.message());
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code missing, failed;
  if (fs::equivalent(a, b, missing)) return true;  // one file under two names (a hard link too)
  fs::path ca = fs::weakly_canonical(fs::absolute(a, failed), failed);
  fs::path cb = fs::weakly_canonical(fs::absolute(b, failed), failed);
  return !failed && ca == cb;
}

// Moves `staged` to `first`, or the first of its numbered names not taken.
std::string claim_free_name(const std::string& staged, const fs::path& first) {
  for (int n = 1; n <= kMostNumbered; ++n) {
    std::string candidate = numbered(first, n);
    if (!move_unless_taken(staged, candidate)) continue;
    if (n > 1) std::printf("%s exists and is kept; this image is %s\n", first.c_str(), candidate.c_str());
    return candidate;
  }
  throw sh::Error(first.string() + " and " + numbered(first, kMostNumbered) +
                  " and every number between exist: name the output with -o");
}

}  // namespace

std::string default_image_path(const std::string& scene) {
  std::string stem = fs::path(scene).stem().string();
  if (stem.empty() || stem == "." || stem == "..") stem = "render";
  return (fs::path("out") / (stem + ".png")).string();
}

void say_if_replacing(const std::string& path) {
  std::error_code ignored;
  if (fs::exists(path, ignored)) std::printf("replacing %s\n", path.c_str());
}

void check_output_path(const std::string& path) {
  fs::path name(path);
  if (name.filename().empty()) throw sh::Error(path + ": names a directory, not a file: name the output file");
  make_parent(name);
  std::string dir = name.has_parent_path() ? name.parent_path().string() : ".";
  long longest = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (longest <= 0) longest = 255;
  std::size_t bytes = name.filename().string().size();
  if (bytes + kTemporarySuffixBytes > static_cast<std::size_t>(longest))
    throw sh::Error(path + ": a file name of " + std::to_string(bytes) + " bytes: at most " +
                    std::to_string(longest - static_cast<long>(kTemporarySuffixBytes)) +
                    " here (the temporary file it is written through needs the rest)");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw sh::Error(path + ": cannot write in its directory " + dir + ": " + std::strerror(errno));
  std::error_code ignored;
  fs::file_status status = fs::symlink_status(path, ignored);
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_symlink(status))
    throw sh::Error(path + ": exists and is not a regular file (a directory, a device or a pipe): name another output");
}

void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    check_output_path(outputs[i]);
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(outputs[i], outputs[j]))
        throw sh::Error(outputs[i] + ": named for two outputs (" + outputs[j] + "): name each its own file");
  }
  check_not_inputs(outputs, inputs);
}

void check_not_inputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  for (const std::string& output : outputs)
    for (const std::string& input : inputs)
      if (std::error_code missing; fs::exists(input, missing) && same_file(output, input))  // a built-in scene: no file
        throw sh::Error(output + ": is an input of this command (" + input + "): name another output");
}

std::string temp_name(const std::string& path) { return path + "." + std::to_string(::getpid()) + ".tmp"; }

void ignore_file_size_limit() { ::signal(SIGXFSZ, SIG_IGN); }

void move_into_place(const std::string& tmp, const std::string& path) {
  std::error_code failed;
  fs::rename(tmp, path, failed);
  if (!failed) return;
  std::remove(tmp.c_str());
  throw sh::Error(path + ": cannot write: " + failed.message());
}

void write_through_temp(const std::string& path, const std::string& bytes) {
  SignalsHeld held;
  std::string tmp = temp_name(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    out << bytes;
    if (!out.flush()) {
      std::remove(tmp.c_str());
      throw sh::Error(path + ": cannot write");
    }
  }
  move_into_place(tmp, path);
}

std::string write_image(const std::string& chosen, const std::string& scene, const FileWriter& write) {
  SignalsHeld held;
  if (!chosen.empty()) {
    check_output_path(chosen);
    say_if_replacing(chosen);
    write(chosen);
    return chosen;
  }
  fs::path first = default_image_path(scene);
  make_parent(first);
  // Written in full under a name of this process's own, then moved to the
  // first free name: no half image under a real name, no file replaced.
  std::string staged = (first.parent_path() / ("." + first.filename().string() + "." + std::to_string(::getpid()))).string();
  write(staged);
  try {
    return claim_free_name(staged, first);
  } catch (...) {
    std::error_code ignored;
    fs::remove(staged, ignored);
    throw;
  }
}

}  // namespace shtrace
