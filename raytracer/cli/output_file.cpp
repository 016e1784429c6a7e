#include "output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <sh/error.hpp>

namespace shtrace {
namespace fs = std::filesystem;

namespace {

constexpr int kMostNumbered = 9999;

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
  if (fs::exists(path)) std::printf("replacing %s\n", path.c_str());
}

void check_output_path(const std::string& path) {
  make_parent(path);
  std::error_code ignored;
  fs::file_status status = fs::symlink_status(path, ignored);
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_symlink(status))
    throw sh::Error(path + ": exists and is not a regular file (a directory, a device or a pipe): name another output");
}

std::string temp_name(const std::string& path) { return path + "." + std::to_string(::getpid()) + ".tmp"; }

void move_into_place(const std::string& tmp, const std::string& path) {
  std::error_code failed;
  fs::rename(tmp, path, failed);
  if (!failed) return;
  std::remove(tmp.c_str());
  throw sh::Error(path + ": cannot write: " + failed.message());
}

void write_through_temp(const std::string& path, const std::string& bytes) {
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
