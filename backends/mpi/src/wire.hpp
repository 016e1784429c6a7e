#pragma once
// Bytes on the wire between ranks: packing values into a message, and
// checked point-to-point and broadcast calls that count what they move.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "sh/backend.hpp"

namespace sh::mpi {

// Message tags of the dynamic phase of a run.
enum Tag : int { kReady = 1, kAssign, kDone, kResult, kFailed, kStats, kBlocks };

// Commands rank 0 broadcasts to the serving ranks.
enum class Command : std::uint32_t { Compile = 1, Run, Shutdown, Forget };

class Packer {
 public:
  template <class T>
  Packer& put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  Packer& put(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    bytes_ += s;
    return *this;
  }
  // A table's view goes without its pointers and owner, which mean nothing
  // on another rank.
  Packer& put(const TableView& t) { return put(t.element).put(t.rank).put(t.dims).put(t.id).put(t.version); }
  Packer& raw(const void* data, std::size_t n) {
    bytes_.append(static_cast<const char*>(data), n);
    return *this;
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  std::string text() {
    auto n = get<std::uint64_t>();
    return std::string(take(n), n);
  }
  const char* take(std::size_t n);

 private:
  const std::string& bytes_;
  std::size_t at_ = 0;
};

template <>
inline TableView Unpacker::get<TableView>() {
  TableView t;
  t.element = get<ir::Type>();
  t.rank = get<int>();
  t.dims = get<std::array<int, 3>>();
  t.id = get<std::uint64_t>();
  t.version = get<std::uint64_t>();
  return t;
}

// sh::Options (spelt out: sh::mpi::Options are the backend's own), each
// backend's own options in their string form, parsed again on arrival.
void pack(Packer& p, const sh::Options& o);
sh::Options unpack_options(Unpacker& u);

// Counted, checked transfers (MPI errors end the job, as MPI's default).
// MPI counts a message's bytes in an int: a message of more than
// message_bytes() goes as pieces of that many bytes from one rank with one
// tag, which arrive in order, and a last piece shorter than the others
// (empty where the message is a whole number of pieces) ends it.
std::size_t message_bytes();  // SH_MPI_MESSAGE_BYTES (1 to 2^31 - 1), else 1 GiB; the same on every rank
struct Traffic {
  std::size_t sent = 0, received = 0;
};
void send(const std::string& bytes, int to, int tag, Traffic& t);
std::string receive(int from, int tag, Traffic& t, int* source = nullptr, int* tag_out = nullptr);
// Rank 0 sends `bytes`; every rank returns them.
std::string broadcast(const std::string& bytes, Traffic& t);

}  // namespace sh::mpi
