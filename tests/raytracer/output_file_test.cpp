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

// In a process of its own (another thread alive there where asked): an
// image written through a temporary of the writer's own, as write_png
// does, whose writer is interrupted at its start.  The process ends by the
// signal, with the image whole in place and nothing beside it.
void expect_the_image_written_despite(void (*interrupt)(), bool another_thread, const std::string& dir_name) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  fs::path dir = fs::path(testing::TempDir()) / dir_name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string path = (dir / "image.png").string();
  EXPECT_EXIT(
      {
        if (another_thread) std::thread([] { std::this_thread::sleep_for(std::chrono::seconds(5)); }).detach();
        shtrace::write_image(path, "scene", [interrupt](const std::string& at) {
          interrupt();
          std::ofstream(at + ".part") << "the whole image";
          fs::rename(at + ".part", at);
        });
        std::exit(0);
      },
      testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(contents(path), "the whole image");
  EXPECT_FALSE(fs::exists(path + ".part"));
  fs::remove_all(dir);
}

TEST(OutputFile, AnInterruptWhileAnImageIsWrittenEndsTheProcessWithTheImageInPlace) {
  expect_the_image_written_despite([] { std::raise(SIGTERM); }, false, "sh_output_interrupted");
}

// The same with another thread alive, which the kernel may pick to take a
// signal sent to the process (a mask on the writing thread alone let it
// end the process mid-write).
TEST(OutputFile, AnInterruptTakenByAnotherThreadStillWaitsForTheImage) {
  expect_the_image_written_despite(
      [] {
        ::kill(::getpid(), SIGTERM);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));  // time for the signal to land anywhere
      },
      true, "sh_output_interrupted_threads");
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
