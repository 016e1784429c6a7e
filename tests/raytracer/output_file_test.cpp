// Where `shtrace` writes its files: an interrupt that comes while a file is
// written ends the process once the file is in place, never with its
// temporary beside it or the file half written.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "output_file.hpp"

namespace {

namespace fs = std::filesystem;

std::string contents(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream read;
  read << in.rdbuf();
  return read.str();
}

TEST(OutputFile, AnInterruptWhileAnImageIsWrittenEndsTheProcessWithTheImageInPlace) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  fs::path dir = fs::path(testing::TempDir()) / "sh_output_interrupted";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string path = (dir / "image.png").string();
  // The writer is interrupted at its start; it writes through a temporary
  // of its own, as write_png does.
  auto interrupted_writer = [](const std::string& at) {
    std::raise(SIGTERM);
    std::ofstream(at + ".part") << "the whole image";
    fs::rename(at + ".part", at);
  };
  EXPECT_EXIT(
      {
        shtrace::write_image(path, "scene", interrupted_writer);
        std::exit(0);
      },
      testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(contents(path), "the whole image");
  EXPECT_FALSE(fs::exists(path + ".part"));
  fs::remove_all(dir);
}

// The same with another thread alive, which the kernel may pick to take a
// signal sent to the process (a mask on the writing thread alone let it
// end the process mid-write).
TEST(OutputFile, AnInterruptTakenByAnotherThreadStillWaitsForTheImage) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  fs::path dir = fs::path(testing::TempDir()) / "sh_output_interrupted_threads";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string path = (dir / "image.png").string();
  auto interrupted_writer = [](const std::string& at) {
    ::kill(::getpid(), SIGTERM);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // time for the signal to land anywhere
    std::ofstream(at + ".part") << "the whole image";
    fs::rename(at + ".part", at);
  };
  EXPECT_EXIT(
      {
        std::thread idle([] { std::this_thread::sleep_for(std::chrono::seconds(5)); });
        idle.detach();
        shtrace::write_image(path, "scene", interrupted_writer);
        std::exit(0);
      },
      testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(contents(path), "the whole image");
  EXPECT_FALSE(fs::exists(path + ".part"));
  fs::remove_all(dir);
}

TEST(OutputFile, TheSignalsHeldWhileWritingAreLetGoAfter) {
  fs::path dir = fs::path(testing::TempDir()) / "sh_output_held";
  fs::remove_all(dir);
  shtrace::write_image((dir / "a.png").string(), "scene", [](const std::string& at) { std::ofstream(at) << "a"; });
  shtrace::write_through_temp((dir / "b.txt").string(), "b");
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
    struct sigaction now {};
    sigaction(s, nullptr, &now);
    EXPECT_EQ(now.sa_handler, SIG_DFL) << s;
  }
  EXPECT_EQ(contents(dir / "b.txt"), "b");
  fs::remove_all(dir);
}

}  // namespace
