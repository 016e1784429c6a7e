#include "wire.hpp"

#include <climits>

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

namespace {
int as_count(std::size_t n) {
  if (n > static_cast<std::size_t>(INT_MAX)) throw Error("mpi backend: a message of " + std::to_string(n) + " bytes is too large; use smaller chunks");
  return static_cast<int>(n);
}
}  // namespace

void send(const std::string& bytes, int to, int tag, Traffic& t) {
  MPI_Send(bytes.data(), as_count(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
  t.sent += bytes.size();
}

std::string receive(int from, int tag, Traffic& t, int* source, int* tag_out) {
  MPI_Status status;
  MPI_Probe(from, tag, MPI_COMM_WORLD, &status);
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::string bytes(static_cast<std::size_t>(count), '\0');
  MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  t.received += bytes.size();
  if (source) *source = status.MPI_SOURCE;
  if (tag_out) *tag_out = status.MPI_TAG;
  return bytes;
}

std::string broadcast(const std::string& bytes, Traffic& t) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  auto size = static_cast<std::uint64_t>(bytes.size());
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  std::string out = rank == 0 ? bytes : std::string(size, '\0');
  MPI_Bcast(out.data(), as_count(size), MPI_BYTE, 0, MPI_COMM_WORLD);
  if (rank == 0) t.sent += size;
  else t.received += size;
  return out;
}

}  // namespace sh::mpi
