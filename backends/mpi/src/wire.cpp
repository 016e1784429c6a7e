#include "wire.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>

#include "sh/error.hpp"

namespace sh::mpi {

const char* Unpacker::take(std::size_t n) {
  if (bytes_.size() - at_ < n) throw Error("mpi backend: truncated message");
  const char* p = bytes_.data() + at_;
  at_ += n;
  return p;
}

void pack(Packer& p, const sh::Options& o) {
  p.put(o.precision).put(o.math).put(o.threads).put(o.max_loop_iterations).put(o.checked).put(o.optimize);
  Settings settings;
  for (const auto& [backend, options] : o.backends)
    for (const auto& [name, value] : options.settings()) settings[backend + "." + name] = value;
  p.put(static_cast<std::uint64_t>(settings.size()));
  for (const auto& [name, value] : settings) p.put(name).put(value);
}

sh::Options unpack_options(Unpacker& u) {
  sh::Options o;
  o.precision = u.get<Precision>();
  o.math = u.get<MathMode>();
  o.threads = u.get<int>();
  o.max_loop_iterations = u.get<std::uint64_t>();
  o.checked = u.get<bool>();
  o.optimize = u.get<bool>();
  auto n = u.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string name = u.text();
    o.set(name, u.text());
  }
  return o;
}

std::size_t message_bytes() {
  static const std::size_t bytes = [] {
    const char* set = std::getenv("SH_MPI_MESSAGE_BYTES");
    if (!set) return std::size_t{1} << 30;
    char* end = nullptr;
    errno = 0;
    unsigned long long n = std::strtoull(set, &end, 10);
    if (errno || end == set || *end || *set == '-' || n < 1 || n > static_cast<unsigned long long>(INT_MAX))
      throw Error(std::string("mpi backend: SH_MPI_MESSAGE_BYTES must be a number of bytes from 1 to 2147483647, not '") +
                  set + "'");
    return static_cast<std::size_t>(n);
  }();
  return bytes;
}

void send(const std::string& bytes, int to, int tag, Traffic& t) {
  std::size_t piece = message_bytes(), at = 0;
  for (std::size_t n = piece; n == piece; at += n) {
    n = std::min(piece, bytes.size() - at);
    MPI_Send(bytes.data() + at, static_cast<int>(n), MPI_BYTE, to, tag, MPI_COMM_WORLD);
  }
  t.sent += bytes.size();
}

std::string receive(int from, int tag, Traffic& t, int* source, int* tag_out) {
  std::string bytes;
  std::size_t piece = message_bytes();
  for (int count = static_cast<int>(piece); static_cast<std::size_t>(count) == piece;) {
    MPI_Status status;
    MPI_Probe(from, tag, MPI_COMM_WORLD, &status);
    MPI_Get_count(&status, MPI_BYTE, &count);
    // The pieces after the first come from the first's rank, with its tag.
    from = status.MPI_SOURCE;
    tag = status.MPI_TAG;
    std::size_t at = bytes.size();
    bytes.resize(at + static_cast<std::size_t>(count));
    MPI_Recv(bytes.data() + at, count, MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  }
  t.received += bytes.size();
  if (source) *source = from;
  if (tag_out) *tag_out = tag;
  return bytes;
}

std::string broadcast(const std::string& bytes, Traffic& t) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  auto size = static_cast<std::uint64_t>(bytes.size());
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  std::string out = rank == 0 ? bytes : std::string(size, '\0');
  for (std::size_t at = 0, piece = message_bytes(); at < size; at += piece)
    MPI_Bcast(out.data() + at, static_cast<int>(std::min<std::size_t>(piece, size - at)), MPI_BYTE, 0, MPI_COMM_WORLD);
  if (rank == 0) t.sent += size;
  else t.received += size;
  return out;
}

}  // namespace sh::mpi
