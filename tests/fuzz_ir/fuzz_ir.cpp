// fuzz_ir: differential fuzzing of the language's IR.  Generates random,
// well-typed programs with data at the extremes (generator.hpp), runs each
// on every backend mode built (every variant, f32 and f64 precision,
// precise math) and compares with the interpreter running the program
// unoptimised, under the ULP contract (exactness.hpp says why inexact
// values stay away from conditions).  Prints every disagreement (the
// program, the data, each side's values) and a summary line.
//
//   fuzz_ir [--programs N] [--seed S] [--backends cpu,opencl,...]
//           [--modes-per-program M] [--minimize K] [--no-accumulators]
//           [--replay PROGRAM_SEED]... [--listing] [--jobs J]
//
// Each program runs on every mode, or with --modes-per-program on M of
// them in turn (CI's budget: a kernel takes 20-150 ms to compile, and a
// program has 18 modes where every backend is built).
// Programs are a deterministic function of --seed; each disagreement names
// its program's own seed, which --replay regenerates alone.  --minimize
// shrinks the first K disagreeing programs to a few statements and one
// element, and counts them by the operations they keep; --listing adds
// what each disagreeing mode was given and made of the minimised program.
//
// The programs run in worker processes (this program with --worker), J at
// once, each on a share of the programs: a backend that crashes or hangs
// (no word for kSilenceSeconds) is counted against the program and mode
// it was running, and a new worker goes on with the next program.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <sh/error.hpp>
#include <sh/sh.hpp>

#include "campaign.hpp"
#include "tally.hpp"

namespace {

using namespace fuzz_ir;
constexpr int kControlFd = 3;        // the worker's line to its supervisor
constexpr int kSilenceSeconds = 600; // longer than any compile and run

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "fuzz_ir: " << why
            << "\nusage: fuzz_ir [--programs N] [--seed S] [--backends a,b] [--modes-per-program M] [--minimize K]\n"
               "               [--no-accumulators] [--replay PROGRAM_SEED]... [--listing] [--jobs J]\n";
  std::exit(2);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::uint64_t number(const std::string& flag, const char* text) {
  char* end = nullptr;
  unsigned long long v = std::strtoull(text, &end, 0);
  if (!*text || *end) usage(flag + " takes a number, not '" + text + "'");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--help") usage("differential fuzzing of the IR");
    bool* flag = a == "--listing" ? &o.listing : a == "--worker" ? &o.worker : nullptr;
    if (flag || a == "--no-accumulators") {
      (flag ? *flag : o.generator.accumulators) = flag != nullptr;
      continue;
    }
    if (i + 1 >= argc) usage("missing a value after " + a);
    const char* v = argv[++i];
    if (a == "--programs") o.programs = number(a, v);
    else if (a == "--seed") o.seed = number(a, v);
    else if (a == "--backends") o.backends = split(v);
    else if (a == "--minimize") o.minimize = static_cast<int>(number(a, v));
    else if (a == "--modes-per-program") o.modes_per_program = number(a, v);
    else if (a == "--replay") o.replay.push_back(number(a, v));
    else if (a == "--start") o.start = number(a, v);
    else if (a == "--end") o.end = number(a, v);
    else if (a == "--jobs") o.jobs = number(a, v);
    else usage("unknown option " + a);
  }
  return o;
}

int worker(const Options& o) {
  std::FILE* control = fdopen(kControlFd, "w");
  try {
    run_campaign(o, control);
  } catch (const sh::Error& e) {  // an unknown backend named, for one
    std::cerr << "fuzz_ir: " << e.what() << "\n";
    return 2;
  }
  return 0;
}

// One worker's share of the programs, [start, end), and what it said.
struct Shard {
  std::size_t start = 0, end = 0;
  pid_t pid = -1;
  int from_worker = -1;
  std::string pending;                 // a line not yet ended
  std::size_t running = 0;             // the program it ran last
  std::string mode;                    // and on what
  std::size_t next = 0;                // the first program it has not finished
  Tally tally;                         // its counts after its last program
  std::chrono::steady_clock::time_point heard;
  bool silenced = false;               // killed for silence
};

class Supervisor {
 public:
  Supervisor(char** argv, const Options& o) : argv_(argv), o_(o), t0_(std::chrono::steady_clock::now()) {
    programs_ = program_seeds(o).size();
    std::size_t jobs = std::max<std::size_t>(1, std::min(o.jobs, programs_));
    for (std::size_t j = 0; j < jobs; ++j) {
      Shard s;
      s.start = o.start + (programs_ - o.start) * j / jobs;
      s.end = o.start + (programs_ - o.start) * (j + 1) / jobs;
      shards_.push_back(s);
    }
  }

  int run() {
    for (Shard& s : shards_) start(s);
    while (any_running()) wait_for_word();
    print_summary(total_, o_.replay.empty() ? o_.seed : 0, seconds());
    return failed_to_start_ ? 2 : total_.clean() ? 0 : 1;
  }

 private:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
  bool any_running() const {
    return std::any_of(shards_.begin(), shards_.end(), [](const Shard& s) { return s.pid > 0; });
  }

  void start(Shard& s) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) std::perror("fuzz_ir: pipe"), std::exit(2);
    s.pid = fork();
    if (s.pid == 0) {
      close(fds[0]);
      dup2(fds[1], kControlFd);  // without O_CLOEXEC: the worker keeps it
      std::vector<std::string> args;
      for (char** a = argv_; *a; ++a) args.emplace_back(*a);
      args.insert(args.end(), {"--worker", "--start", std::to_string(s.start), "--end", std::to_string(s.end)});
      std::vector<char*> cargs;
      for (std::string& a : args) cargs.push_back(a.data());
      cargs.push_back(nullptr);
      execv("/proc/self/exe", cargs.data());
      std::perror("fuzz_ir: exec");
      _exit(2);
    }
    close(fds[1]);
    s.from_worker = fds[0];
    s.running = s.next = s.start;
    s.mode.clear();
    s.tally = Tally{};
    s.heard = std::chrono::steady_clock::now();
    s.silenced = false;
  }

  void wait_for_word() {
    std::vector<pollfd> polls;
    for (const Shard& s : shards_)
      if (s.pid > 0) polls.push_back({s.from_worker, POLLIN, 0});
    poll(polls.data(), polls.size(), 1000);
    for (Shard& s : shards_) {
      if (s.pid <= 0) continue;
      pollfd p{s.from_worker, POLLIN, 0};
      if (poll(&p, 1, 0) > 0) {
        if (!read_lines(s)) ended(s);
      } else if (std::chrono::steady_clock::now() - s.heard > std::chrono::seconds(kSilenceSeconds) && !s.silenced) {
        kill(s.pid, SIGKILL);
        s.silenced = true;
      }
    }
  }

  // Returns false at the end of the worker's line.
  bool read_lines(Shard& s) {
    char buffer[4096];
    ssize_t n = read(s.from_worker, buffer, sizeof buffer);
    if (n <= 0) return false;
    s.heard = std::chrono::steady_clock::now();
    s.pending.append(buffer, static_cast<std::size_t>(n));
    for (std::size_t eol; (eol = s.pending.find('\n')) != std::string::npos; s.pending.erase(0, eol + 1)) hear(s, s.pending.substr(0, eol));
    return true;
  }

  void hear(Shard& s, const std::string& line) {
    std::istringstream in(line);
    std::string what;
    std::size_t k = 0;
    in >> what >> k;
    if (what == "run") {
      s.running = k;
      std::getline(in >> std::ws, s.mode);
    } else if (what == "done") {
      s.next = k + 1;
      std::string rest;
      std::getline(in >> std::ws, rest);
      s.tally = Tally::parse(rest);
      if (++done_ % 1000 == 0) progress();
    }
  }

  void progress() {
    Tally now = total_;
    for (const Shard& s : shards_) now += s.tally;
    std::printf("progress: %zu of %zu programs, %zu disagreements in %zu programs, %zu invalid, %.0f s\n", done_,
                programs_ - o_.start, now.disagreements, now.failing_programs, now.invalid, seconds());
    std::fflush(stdout);
  }

  // The worker's line closed: it finished, said why it could not go on,
  // crashed or was killed for silence.
  void ended(Shard& s) {
    close(s.from_worker);
    int status = 0;
    waitpid(s.pid, &status, 0);
    s.pid = -1;
    total_ += s.tally;
    s.tally = Tally{};
    bool exited = !s.silenced && WIFEXITED(status);
    if (exited && WEXITSTATUS(status) == 2) {
      failed_to_start_ = true;  // it said why on stderr
      return;
    }
    if (exited && s.next >= s.end) return;
    if (exited) {
      std::fprintf(stderr, "fuzz_ir: a worker ended after program %zu of [%zu, %zu) without a crash\n", s.next, s.start, s.end);
      failed_to_start_ = true;
      return;
    }
    count_crash(s, s.silenced ? "hang" : "crash (signal " + std::to_string(WTERMSIG(status)) + ")");
    ++done_;
    s.start = s.running + 1;
    if (s.start < s.end) start(s);
  }

  void count_crash(const Shard& s, const std::string& how) {
    std::uint64_t seed = program_seeds(o_)[s.running];
    std::string mode = s.mode.substr(0, s.mode.find(' '));
    std::printf("=== %s: program seed %llu (%s) on %s\n", how.c_str(), static_cast<unsigned long long>(seed),
                replay_command(seed, o_.generator).c_str(), s.mode.c_str());
    ++total_.programs;
    ++total_.disagreements;
    ++total_.failing_programs;
    ++(how == "hang" ? total_.hangs : total_.crashes);
    ++total_.by_mode[mode];
    ++total_.by_backend[mode.substr(0, mode.find('_'))];
    std::fflush(stdout);
  }

  char** argv_;
  const Options& o_;
  std::chrono::steady_clock::time_point t0_;
  std::size_t programs_ = 0, done_ = 0;
  std::vector<Shard> shards_;
  Tally total_;
  bool failed_to_start_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  // Tens of thousands of kernels compiled once each: none belongs in the
  // cpu backend's or pocl's on-disk cache.
  setenv("SH_CACHE_DIR", "off", 1);
  setenv("POCL_KERNEL_CACHE", "0", 1);
  Options o = parse(argc, argv);
  return o.worker ? worker(o) : Supervisor(argv, o).run();
}
