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
//           [--replay PROGRAM_SEED]... [--listing]
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
// The programs run in a worker process (this program with --worker): a
// backend that crashes or hangs (no word for kSilenceSeconds) is counted
// against the program and mode it was running, and a new worker goes on
// with the next program.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

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
               "               [--no-accumulators] [--replay PROGRAM_SEED]... [--listing]\n";
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

// What the supervisor hears from one worker.
struct Heard {
  std::size_t next = 0;           // the first program it did not finish
  std::size_t running = 0;        // the program it ran last
  std::string mode;               // and on what
  Tally tally;                    // its counts after its last program
};

void hear(const std::string& line, Heard& h, Tally total, std::size_t programs, double seconds) {
  std::istringstream in(line);
  std::string what;
  std::size_t k = 0;
  in >> what >> k;
  if (what == "run") {
    h.running = k;
    std::getline(in >> std::ws, h.mode);
  } else if (what == "done") {
    h.next = k + 1;
    std::string rest;
    std::getline(in >> std::ws, rest);
    h.tally = Tally::parse(rest);
    total += h.tally;
    if (h.next % 1000 == 0)
      std::printf("progress: %zu of %zu programs, %zu disagreements in %zu programs, %zu invalid, %.0f s\n", h.next, programs,
                  total.disagreements, total.failing_programs, total.invalid, seconds), std::fflush(stdout);
  }
}

// Starts a worker at program `start`; returns its pid and the read end of
// its control line.
pid_t start_worker(char** argv, std::size_t start, int& from_worker) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) std::perror("fuzz_ir: pipe"), std::exit(2);
  pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    dup2(fds[1], kControlFd);  // without O_CLOEXEC: the worker keeps it
    std::vector<std::string> args;
    for (char** a = argv; *a; ++a) args.emplace_back(*a);
    args.insert(args.end(), {"--worker", "--start", std::to_string(start)});
    std::vector<char*> cargs;
    for (std::string& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    execv("/proc/self/exe", cargs.data());
    std::perror("fuzz_ir: exec");
    _exit(2);
  }
  close(fds[1]);
  from_worker = fds[0];
  return pid;
}

// Reads a worker's lines until it ends or falls silent (then kills it).
// Returns whether it fell silent.
bool follow(int from_worker, pid_t pid, Heard& h, const Tally& total, std::size_t programs,
            std::chrono::steady_clock::time_point t0) {
  std::string pending;
  char buffer[4096];
  for (;;) {
    pollfd p{from_worker, POLLIN, 0};
    if (poll(&p, 1, kSilenceSeconds * 1000) == 0) {
      kill(pid, SIGKILL);
      return true;
    }
    ssize_t n = read(from_worker, buffer, sizeof buffer);
    if (n <= 0) return false;
    pending.append(buffer, static_cast<std::size_t>(n));
    for (std::size_t eol; (eol = pending.find('\n')) != std::string::npos; pending.erase(0, eol + 1))
      hear(pending.substr(0, eol), h, total, programs,
           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
}

void count_crash(const Heard& h, const Options& o, const std::string& how, Tally& total) {
  std::uint64_t seed = program_seeds(o)[h.running];
  std::string mode = h.mode.substr(0, h.mode.find(' '));
  std::printf("=== %s: program seed %llu (%s) on %s\n", how.c_str(), static_cast<unsigned long long>(seed),
              replay_command(seed, o.generator).c_str(), h.mode.c_str());
  ++total.programs;
  ++total.disagreements;
  ++total.failing_programs;
  ++(how == "hang" ? total.hangs : total.crashes);
  ++total.by_mode[mode];
  ++total.by_backend[mode.substr(0, mode.find('_'))];
  std::fflush(stdout);
}

int supervise(char** argv, const Options& o) {
  auto t0 = std::chrono::steady_clock::now();
  std::size_t programs = program_seeds(o).size();
  Tally total;
  for (std::size_t start = o.start; start < programs || start == o.start;) {
    int from_worker = -1;
    pid_t pid = start_worker(argv, start, from_worker);
    Heard h;
    h.next = h.running = start;
    bool silent = follow(from_worker, pid, h, total, programs, t0);
    close(from_worker);
    int status = 0;
    waitpid(pid, &status, 0);
    total += h.tally;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 2) return 2;  // it said why
    if (h.next >= programs && !silent && WIFEXITED(status)) break;
    if (!silent && WIFEXITED(status) && h.next < programs) {
      std::fprintf(stderr, "fuzz_ir: the worker ended after program %zu of %zu without a crash\n", h.next, programs);
      return 2;
    }
    count_crash(h, o, silent ? "hang" : "crash (signal " + std::to_string(WTERMSIG(status)) + ")", total);
    start = h.running + 1;
  }
  print_summary(total, o.replay.empty() ? o.seed : 0, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return total.clean() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Tens of thousands of kernels compiled once each: none belongs in the
  // cpu backend's or pocl's on-disk cache.
  setenv("SH_CACHE_DIR", "off", 1);
  setenv("POCL_KERNEL_CACHE", "0", 1);
  Options o = parse(argc, argv);
  return o.worker ? worker(o) : supervise(argv, o);
}
