// What the runtime keeps on disk: the passes' result for a program as
// recorded, read back by a later compile of it, and replaced where a file
// is damaged; and the build ID that keys it to this build.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <sh/detail/disk_cache.hpp>
#include <sh/sh.hpp>

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
  Program p = SH_BEGIN_PROGRAM("kept") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f + 1.0f;
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
  EXPECT_EQ(y.values(), (std::vector<float>{3, 5}));
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
