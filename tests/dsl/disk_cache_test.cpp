// What the runtime keeps on disk: the passes' result for a program as
// recorded, read back by a later compile of it, and replaced where a file
// is damaged; and the build ID that keys it to this build.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <sh/detail/disk_cache.hpp>
#include <sh/sh.hpp>

#include "../common/fresh.hpp"

namespace {

using namespace sh;
namespace fs = std::filesystem;

std::vector<fs::path> passes_files(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().filename().string().rfind("passes-", 0) == 0) out.push_back(f.path());
  return out;
}

std::string contents(const fs::path& p) { return detail::read_cache_file(p.string()).value_or(""); }

TEST(DiskCache, ThePassesResultIsKeptReadBackAndReplacedWhereDamaged) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_disk_cache_test";
  fs::remove_all(dir);
  setenv("SH_CACHE_DIR", dir.c_str(), 1);
  const float c = fresh_constant();  // a program no earlier run compiled
  Program p = SH_BEGIN_PROGRAM("kept") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f + c;
  } SH_END;
  Channel<Attrib1f> x(std::vector<float>{1, 2}), y;
  // Each run below misses the process's own kernels (another backend or
  // option), so the runtime reaches the disk.
  run(p, {x}, {y}, backend("interp"));
  std::vector<fs::path> files = passes_files(dir);
  ASSERT_EQ(files.size(), 1u);
  std::string kept = contents(files[0]);
  EXPECT_EQ(ir::deserialize(kept).name, "kept");

  Options checked;
  checked.checked = true;  // another key: a second file
  run(p, {x}, {y}, backend("interp", checked));
  EXPECT_EQ(passes_files(dir).size(), 2u);

  // Damaged: the passes run again, and their result replaces it.
  std::ofstream(files[0], std::ios::binary) << "SHIR damaged";
  std::string other;
  for (const BackendInfo& b : backends())
    if (b.name != "interp") other = b.name;
  ASSERT_FALSE(other.empty()) << "a second backend to miss the process's kernels with";
  run(p, {x}, {y}, backend(other));
  EXPECT_EQ(y.values(), (std::vector<float>{2 + c, 4 + c}));
  EXPECT_EQ(contents(files[0]), kept);
  unsetenv("SH_CACHE_DIR");
  fs::remove_all(dir);
}

// A file whose bytes changed on disk, or that was cut short, reads as none:
// a damaged entry is computed afresh, never used (machine code would run).
TEST(DiskCache, AFileThatNoLongerMatchesItsChecksumReadsAsNone) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_disk_cache_checksum";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string path = (dir / "entry").string(), bytes(4096, 'x');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  detail::write_cache_file(path, bytes);
  EXPECT_EQ(detail::read_cache_file(path), bytes);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(2000);
    f.put('\x5a');
  }
  EXPECT_FALSE(detail::read_cache_file(path)) << "one byte changed in the middle";
  detail::write_cache_file(path, bytes);
  fs::resize_file(path, 3000);
  EXPECT_FALSE(detail::read_cache_file(path)) << "cut short";
  fs::resize_file(path, 3);
  EXPECT_FALSE(detail::read_cache_file(path)) << "shorter than a checksum";
  detail::write_cache_file(path, "");
  EXPECT_EQ(detail::read_cache_file(path), "") << "an empty entry is an entry";
  fs::remove_all(dir);
}

// Another user who can write in the directory could plant machine code
// that would run as ours: a directory of ours that others could write in is
// made ours alone, another user's is not used (a run says why, once), and a
// file in it that another user owns reads as none.
TEST(DiskCache, OnlyThisUsersDirectoryAndFilesAreUsed) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_disk_cache_shared";
  fs::remove_all(dir);
  setenv("SH_CACHE_DIR", dir.c_str(), 1);
  ASSERT_TRUE(detail::cache_directory());
  auto others_write = [&] {
    return (fs::status(dir).permissions() & (fs::perms::group_write | fs::perms::others_write)) != fs::perms::none;
  };
  EXPECT_EQ(fs::status(dir).permissions() & (fs::perms::group_all | fs::perms::others_all), fs::perms::none)
      << "made for its owner alone";
  fs::permissions(dir, fs::perms::all);
  testing::internal::CaptureStderr();
  EXPECT_TRUE(detail::cache_directory());
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_FALSE(others_write()) << "ours, made ours alone";
  if (geteuid() == 0) {  // root can give files and directories away
    std::string planted = (dir / "cpu-1234").string();
    detail::write_cache_file(planted, "machine code");
    ASSERT_TRUE(detail::read_cache_file(planted));
    ASSERT_EQ(chown(planted.c_str(), 65534, 65534), 0);
    EXPECT_FALSE(detail::read_cache_file(planted)) << "another user's file";
    fs::path other = dir / fresh_name("other");
    fs::create_directory(other);
    ASSERT_EQ(chown(other.c_str(), 65534, 65534), 0);
    setenv("SH_CACHE_DIR", other.c_str(), 1);
    testing::internal::CaptureStderr();
    EXPECT_FALSE(detail::cache_directory());
    EXPECT_FALSE(detail::cache_directory());
    std::string said = testing::internal::GetCapturedStderr();
    EXPECT_NE(said.find("belongs to another user"), std::string::npos) << said;
    EXPECT_EQ(said.find(other.string()), said.rfind(other.string())) << "said once: " << said;
  }
  fs::path file = fs::path(testing::TempDir()) / fresh_name("sh_disk_cache_file");
  std::ofstream(file) << "a file";
  setenv("SH_CACHE_DIR", file.c_str(), 1);
  testing::internal::CaptureStderr();
  EXPECT_FALSE(detail::cache_directory());
  std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("not a directory"), std::string::npos) << said;
  unsetenv("SH_CACHE_DIR");
  fs::remove_all(dir);
  fs::remove(file);
}

std::uintmax_t entries_bytes(const fs::path& dir) {
  std::uintmax_t total = 0;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().filename().string().rfind("passes-", 0) == 0) total += f.file_size();
  return total;
}

// Past its limit the cache drops what was used longest ago, reading counting
// as a use; temporaries of killed writers go too, and nothing that is not
// named as an entry is touched.
TEST(DiskCache, PrunedToThreeQuartersOfItsLimitLeastRecentlyUsedFirst) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_disk_cache_prune";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A file of the user's, two hours old: a stamp by its name would be due.
  std::ofstream(dir / "pruned") << "a file of the user's, whatever its name";
  auto now = fs::file_time_type::clock::now();
  fs::last_write_time(dir / "pruned", now - std::chrono::hours(2));
  std::string kib(1024, 'k');
  for (int i = 0; i < 8; ++i) {
    std::string path = (dir / ("passes-" + std::to_string(i))).string();
    detail::write_cache_file(path, kib);
    fs::last_write_time(path, now - std::chrono::minutes(60 - i));
  }
  std::ofstream(dir / "notes.txt") << std::string(100000, 'n');
  std::ofstream(dir / "cpu-ABC.o") << "upper case: not a name the cache gives";
  std::ofstream(dir / "cpu-ab.o.tmp12.0") << "killed mid-write";
  fs::last_write_time(dir / "cpu-ab.o.tmp12.0", now - std::chrono::minutes(11));
  std::ofstream(dir / "cpu-cd.o.tmp13.0") << "being written";
  EXPECT_TRUE(detail::read_cache_file((dir / "passes-0").string())) << "the oldest, used now";
  detail::prune_cache(dir.string(), 4 * 1032);
  detail::write_cache_file((dir / "passes-8").string(), kib);
  std::vector<std::string> left;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().filename().string()[0] != '.') left.push_back(f.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"cpu-ABC.o", "cpu-cd.o.tmp13.0", "notes.txt", "passes-0", "passes-6",
                                            "passes-7", "passes-8", "pruned"}));
  std::ifstream kept(dir / "pruned");
  std::string line;
  std::getline(kept, line);
  EXPECT_EQ(line, "a file of the user's, whatever its name");
  fs::remove_all(dir);
}

// Stores keep the cache near its limit without a scan at every store.
TEST(DiskCache, StoresKeepTheCacheNearItsLimit) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_disk_cache_limit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  setenv("SH_CACHE_LIMIT_MB", "1", 1);
  EXPECT_EQ(detail::cache_limit_bytes(), 1u << 20);
  std::string quarter(256 << 10, 'q');
  for (int i = 0; i < 16; ++i) detail::write_cache_file((dir / ("passes-" + std::to_string(i))).string(), quarter);
  EXPECT_LE(entries_bytes(dir), (1u << 20) + 2 * (quarter.size() + 8));
  EXPECT_TRUE(fs::exists(dir / "passes-15"));
  EXPECT_FALSE(fs::exists(dir / "passes-0"));
  const std::string bad = fresh_name("-3");  // said once a process for each value
  setenv("SH_CACHE_LIMIT_MB", bad.c_str(), 1);
  testing::internal::CaptureStderr();
  EXPECT_EQ(detail::cache_limit_bytes(), std::uintmax_t{1024} << 20) << "a bad setting keeps the default";
  EXPECT_EQ(detail::cache_limit_bytes(), std::uintmax_t{1024} << 20);
  std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("SH_CACHE_LIMIT_MB='" + bad + "' is not a number of MiB"), std::string::npos) << said;
  EXPECT_EQ(said.find(bad), said.rfind(bad)) << "said once: " << said;
  unsetenv("SH_CACHE_LIMIT_MB");
  fs::remove_all(dir);
}

TEST(DiskCache, OffMeansNoFiles) {
  setenv("SH_CACHE_DIR", "off", 1);
  EXPECT_FALSE(detail::cache_directory());
  EXPECT_FALSE(detail::cache_path("passes", "key"));
  unsetenv("SH_CACHE_DIR");
}

TEST(DiskCache, ThisBuildHasAnId) {
  std::string id = detail::build_id(reinterpret_cast<const void*>(&detail::build_id));
  EXPECT_EQ(id.size(), 40u) << "a GNU build ID is 20 bytes: " << id;
  EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
  EXPECT_EQ(detail::build_id(nullptr), "");
}

}  // namespace
