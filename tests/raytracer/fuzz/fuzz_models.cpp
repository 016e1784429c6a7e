// fuzz_models: renders malformed model and scene files with shtrace, each in
// a process of its own under a timeout, and counts how each ended.  Every
// case must end in a render or a clean error (exit 1-125, a message naming
// the file, no image written) within the timeout: a signal, a hang, an error
// that does not name the file, or a certainly invalid file rendered without
// a word fails the run.
//
//   fuzz_models --shtrace build/raytracer/shtrace --cases 300 --seed 1
//               [--jobs 2] [--timeout 20] [--replay DIR]... [--keep DIR]
//               [--shtrace-arg ARG]...
//
// --timeout is CPU seconds of the case's processes (wall-clock time ten
// times as long stops one that sleeps); shtrace's own --load-seconds bounds
// a model load in wall-clock time.
// The cases are a deterministic function of --seed; --replay runs every file
// of a directory as it is (regressions, assimp's invalid models); --keep
// saves each failing case there, named after what went wrong.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "mutate.hpp"
#include "seeds.hpp"

namespace {

namespace fs = std::filesystem;
using sh::fuzz::Case;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string shtrace;
  std::size_t cases = 300;
  std::uint64_t seed = 1;
  std::size_t jobs = 2;
  double timeout = 20;
  std::vector<std::string> replay;
  std::string keep;
  std::vector<std::string> shtrace_args;
};

enum class Outcome { rendered, warned, clean_error, crash, hang, unnamed_error, silent_accept, wrote_on_error, no_image };

const char* name(Outcome o) {
  switch (o) {
    case Outcome::rendered: return "rendered";
    case Outcome::warned: return "invalid, rendered with a warning naming the file";
    case Outcome::clean_error: return "clean error";
    case Outcome::crash: return "crash";
    case Outcome::hang: return "hang";
    case Outcome::unnamed_error: return "error not naming the file";
    case Outcome::silent_accept: return "silent accept";
    case Outcome::wrote_on_error: return "image written despite an error";
    case Outcome::no_image: return "success without an image";
  }
  return "?";
}

bool bad(Outcome o) { return o != Outcome::rendered && o != Outcome::warned && o != Outcome::clean_error; }

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

// CPU seconds the processes of a group have used (shtrace and its loading
// child).  A case's clock: on a loaded machine, or under nice, wall-clock
// time says more about the neighbours than about the case.
double group_cpu_seconds(pid_t group) {
  static const double tick = static_cast<double>(::sysconf(_SC_CLK_TCK));
  double total = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    std::string stat = read_file(entry.path() / "stat");
    std::size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream fields(stat.substr(close + 2));
    std::string state;
    long ppid = 0, pgrp = 0;
    fields >> state >> ppid >> pgrp;
    if (pgrp != group) continue;
    std::string skip;
    for (int i = 6; i < 14; ++i) fields >> skip;  // session .. cmajflt
    double utime = 0, stime = 0, cutime = 0, cstime = 0;
    fields >> utime >> stime >> cutime >> cstime;
    total += (utime + stime + cutime + cstime) / tick;
  }
  return total;
}

// One case on its way: the files in a directory of its own, shtrace running.
struct Job {
  Case c;
  std::string file;  // the case's file name, which an error must mention
  fs::path dir;
  pid_t pid = -1;
  Clock::time_point started, cpu_checked;
  double cpu_seconds = 0;
};

// Past the timeout in CPU time, or in wall-clock time `kWallFactor` times
// as long (a case that sleeps or deadlocks uses no CPU).
constexpr double kWallFactor = 10;

bool too_long(Job& job, double timeout) {
  auto now = Clock::now();
  if (std::chrono::duration<double>(now - job.started).count() > kWallFactor * timeout) return true;
  if (now - job.cpu_checked < std::chrono::milliseconds(250)) return false;
  job.cpu_checked = now;
  job.cpu_seconds = std::max(job.cpu_seconds, group_cpu_seconds(job.pid));
  return job.cpu_seconds > timeout;
}

// Runs shtrace on the job's file in a process group of its own (so that a
// hang is killed with its loading child), output to files in the job's
// directory.
pid_t start(const Options& o, Job& job) {
  std::vector<std::string> args = {o.shtrace, "render", "--scene", job.file, "--size", "8x8", "--backend", "interp",
                                   "--reflections", "1", "--samples", "1", "-o", "out.png"};
  args.insert(args.end(), o.shtrace_args.begin(), o.shtrace_args.end());
  std::fflush(stdout);  // else the child's copy of the buffer comes out twice
  pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    if (::chdir(job.dir.c_str()) != 0) ::_exit(127);
    int out = ::open("stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644), err = ::open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0 || ::dup2(out, STDOUT_FILENO) < 0 || ::dup2(err, STDERR_FILENO) < 0) ::_exit(127);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (pid > 0) ::setpgid(pid, pid);
  return pid;
}

Outcome classify(const Job& job, int status) {
  if (WIFSIGNALED(status)) return Outcome::crash;
  int code = WEXITSTATUS(status);
  bool image = fs::exists(job.dir / "out.png");
  std::string errors = read_file(job.dir / "stderr.txt");
  if (code == 0) {
    if (!image) return Outcome::no_image;
    if (!job.c.must_fail) return Outcome::rendered;
    // An importer that repairs what it reads (OFF clamps indices) may
    // render, provided a warning names the file.
    return errors.find("warning: " + job.file) != std::string::npos ? Outcome::warned : Outcome::silent_accept;
  }
  if (code > 125) return Outcome::crash;
  if (errors.find(job.file) == std::string::npos) return Outcome::unnamed_error;
  return image ? Outcome::wrote_on_error : Outcome::clean_error;
}

struct Tally {
  std::map<Outcome, std::size_t> total;
  std::multimap<double, std::string> slowest;  // seconds -> case, the longest few
  std::map<std::string, std::map<Outcome, std::size_t>> by_format;
  std::size_t cases = 0;

  void add(const std::string& format, Outcome o) {
    ++total[o];
    ++by_format[format][o];
    ++cases;
  }
};

void report_bad(const Options& o, const Job& job, Outcome outcome, std::size_t index) {
  std::string stderr_text = read_file(job.dir / "stderr.txt");
  if (stderr_text.size() > 400) stderr_text = stderr_text.substr(0, 400) + "...";
  std::printf("%s: case %zu (%s: %s)\n  stderr: %s\n", name(outcome), index, job.c.format.c_str(), job.c.mutations.c_str(),
              stderr_text.c_str());
  if (o.keep.empty()) return;
  fs::create_directories(o.keep);
  std::string kind = name(outcome);
  for (char& ch : kind)
    if (ch == ' ') ch = '-';
  fs::path saved = fs::path(o.keep) / (job.c.format + "-" + kind + "-" + std::to_string(o.seed) + "-" + std::to_string(index) +
                                       "." + job.c.extension);
  write_file(saved, job.c.bytes);
  std::printf("  saved as %s\n", saved.c_str());
}

// The cases: every file of the replay directories first, then the mutants.
std::vector<Case> make_cases(const Options& o) {
  std::vector<Case> cases;
  for (const std::string& dir : o.replay) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      std::string ext = f.extension().string();
      cases.push_back({"replay", ext.empty() ? "" : ext.substr(1), read_file(f), f.filename().string(), false});
    }
  }
  std::mt19937_64 rng(o.seed);
  std::vector<sh::fuzz::Seed> seeds = sh::fuzz::seeds();
  for (std::size_t i = 0; i < o.cases; ++i) cases.push_back(sh::fuzz::mutate(seeds[i % seeds.size()], rng));
  return cases;
}

// Gets the job's directory ready: the case's file, the mesh JSON seeds refer to.
void prepare(Job& job, const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  job.dir = dir;
  job.file = job.c.format == "replay" ? job.c.mutations : "case." + job.c.extension;
  write_file(dir / job.file, job.c.bytes);
  write_file(dir / sh::fuzz::kSceneMeshName, sh::fuzz::scene_mesh());
}

void print_counts(const Tally& t);

std::size_t count(const std::map<Outcome, std::size_t>& m, Outcome o) {
  auto it = m.find(o);
  return it == m.end() ? 0 : it->second;
}

Tally run_all(const Options& o, const std::vector<Case>& cases, const fs::path& work) {
  Tally tally;
  std::vector<Job> slots(o.jobs);
  std::vector<std::size_t> index_of(o.jobs);
  std::size_t next = 0, running = 0;
  while (next < cases.size() || running > 0) {
    for (std::size_t s = 0; s < o.jobs && next < cases.size(); ++s) {
      if (slots[s].pid > 0) continue;
      slots[s].c = cases[next];
      index_of[s] = next++;
      prepare(slots[s], work / ("job" + std::to_string(s)));
      slots[s].started = slots[s].cpu_checked = Clock::now();
      slots[s].cpu_seconds = 0;
      slots[s].pid = start(o, slots[s]);
      if (slots[s].pid > 0) ++running;
    }
    for (std::size_t s = 0; s < o.jobs; ++s) {
      Job& job = slots[s];
      if (job.pid <= 0) continue;
      int status = 0;
      pid_t done = ::waitpid(job.pid, &status, WNOHANG);
      bool late = done == 0 && too_long(job, o.timeout);
      if (done == 0 && !late) continue;
      Outcome outcome;
      if (done == 0) {
        ::kill(-job.pid, SIGKILL);
        ::waitpid(job.pid, &status, 0);
        outcome = Outcome::hang;
      } else {
        ::kill(-job.pid, SIGKILL);  // a loading child left behind, if any
        outcome = classify(job, status);
      }
      tally.add(job.c.format == "replay" ? "replay" : job.c.format, outcome);
      tally.slowest.emplace(std::chrono::duration<double>(Clock::now() - job.started).count(),
                            job.c.format + ": " + job.c.mutations.substr(0, 100));
      if (tally.slowest.size() > 3) tally.slowest.erase(tally.slowest.begin());
      if (bad(outcome)) report_bad(o, job, outcome, index_of[s]);
      job.pid = -1;
      --running;
      if (tally.cases % 1000 == 0) print_counts(tally);  // a long run shows how it goes
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return tally;
}

void print(const Tally& t) {
  for (const auto& [format, m] : t.by_format) {
    std::printf("  %-10s", format.c_str());
    for (Outcome o : {Outcome::rendered, Outcome::warned, Outcome::clean_error, Outcome::crash, Outcome::hang, Outcome::unnamed_error,
                      Outcome::silent_accept, Outcome::wrote_on_error, Outcome::no_image})
      if (count(m, o) > 0) std::printf(" %zu %s,", count(m, o), name(o));
    std::printf("\n");
  }
  for (const auto& [seconds, what] : t.slowest) std::printf("  slow: %.1f s  %s\n", seconds, what.c_str());
  print_counts(t);
}

void print_counts(const Tally& t) {
  std::size_t other = count(t.total, Outcome::unnamed_error) + count(t.total, Outcome::silent_accept) +
                      count(t.total, Outcome::wrote_on_error) + count(t.total, Outcome::no_image);
  std::printf("%zu cases: %zu rendered, %zu clean errors, %zu crashes, %zu hangs, %zu other failures "
              "(of the rendered, %zu certainly invalid with a warning naming the file)\n",
              t.cases, count(t.total, Outcome::rendered) + count(t.total, Outcome::warned), count(t.total, Outcome::clean_error),
              count(t.total, Outcome::crash), count(t.total, Outcome::hang), other, count(t.total, Outcome::warned));
  std::fflush(stdout);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "fuzz_models: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--shtrace") o.shtrace = value();
    else if (a == "--cases") o.cases = std::stoull(value());
    else if (a == "--seed") o.seed = std::stoull(value());
    else if (a == "--jobs") o.jobs = std::max<std::size_t>(1, std::stoull(value()));
    else if (a == "--timeout") o.timeout = std::stod(value());
    else if (a == "--replay") o.replay.push_back(value());
    else if (a == "--keep") o.keep = value();
    else if (a == "--shtrace-arg") o.shtrace_args.push_back(value());
    else {
      std::fprintf(stderr, "fuzz_models: unknown option %s (see the comment at the top of fuzz_models.cpp)\n", a.c_str());
      std::exit(2);
    }
  }
  if (o.shtrace.empty()) {
    std::fprintf(stderr, "fuzz_models: --shtrace PATH is required\n");
    std::exit(2);
  }
  o.shtrace = fs::absolute(o.shtrace).string();
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse(argc, argv);
  fs::path work = fs::temp_directory_path() / ("sh_fuzz_models_" + std::to_string(::getpid()));
  std::vector<Case> cases = make_cases(o);
  auto begun = Clock::now();
  Tally t = run_all(o, cases, work);
  fs::remove_all(work);
  print(t);
  std::printf("seed %llu, %zu jobs, %.1f s\n", static_cast<unsigned long long>(o.seed), o.jobs,
              std::chrono::duration<double>(Clock::now() - begun).count());
  std::size_t failures = 0;
  for (const auto& [outcome, n] : t.total)
    if (bad(outcome)) failures += n;
  return failures == 0 ? 0 : 1;
}
