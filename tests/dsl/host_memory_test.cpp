// Host memory's front end, the same on every backend: what does not fit is
// an sh::Error naming the channel or table, the bytes given and the bytes
// needed; Sh's reference-counted pointer semantics.  The runs on memory are
// in the conformance suite (conformance/host_memory.cpp), on every backend.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include <sh/compat.hpp>

namespace {

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const sh::Error& e) {
    return e.what();
  }
  return "(no error)";
}

ShProgram copy_program() {
  return SH_BEGIN_PROGRAM("copy") {
    ShInputAttrib1f x;
    ShOutputAttrib1f y;
    y = x;
  } SH_END;
}

TEST(HostMemory, ChannelTooSmallNamesTheBytes) {
  std::vector<float> data(5);
  ShHostMemoryPtr memory = new ShHostMemory(data.size() * sizeof(float), data.data(), SH_FLOAT);
  std::string e = error_of([&] { ShChannel<ShAttrib3f> c(memory, 2); });
  EXPECT_NE(e.find("a channel of f32x3"), std::string::npos) << e;
  EXPECT_NE(e.find("2 elements need 24 bytes; the memory holds 20"), std::string::npos) << e;
  ShChannel<ShAttrib3f> fits(memory, 1);
  EXPECT_EQ(fits.count(), 1u);
}

// Element counts whose bytes pass what a size_t counts are refused, not
// wrapped to a small allocation that every later check would trust.
TEST(HostMemory, CountsWhoseBytesWrapAreRefused) {
  const std::size_t wraps = std::size_t{1} << 60;  // x 16 bytes = 2^64
  std::string shaped = error_of([] { sh::Channel<sh::Attrib4f> c; c.shape(std::size_t{1} << 30, std::size_t{1} << 30); });
  EXPECT_NE(shaped.find("1152921504606846976 elements of f32x4 are more bytes than memory can hold"), std::string::npos)
      << shaped;
  EXPECT_NE(error_of([&] { sh::Channel<sh::Attrib4f> c(wraps); }).find("more bytes than memory"), std::string::npos);
  std::vector<float> data(16);
  ShHostMemoryPtr memory = new ShHostMemory(data.size() * sizeof(float), data.data(), SH_FLOAT);
  EXPECT_NE(error_of([&] { ShChannel<ShAttrib4f> c(memory, wraps); }).find("more bytes than memory"), std::string::npos);
  EXPECT_NE(error_of([] { sh::Table2D<sh::Attrib4f> t(1 << 30, 1 << 30); }).find("more bytes than memory"),
            std::string::npos);
}

// A count whose bytes a size_t holds but no process can (2^48 bytes, past
// x86-64's 2^47 of user addresses) is an error naming it, not a
// std::bad_alloc from somewhere.
TEST(HostMemory, CountsPastTheAddressSpaceAreErrorsNamingThem) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's operator new aborts where memory runs out, where the main build's throws";
#endif
  // Bytes a size_t holds whose word count, rounded up, does not: no words
  // at all were allocated for them.
  std::string most = error_of([] { sh::Channel<sh::Attrib1f> c(SIZE_MAX / 4); });
  EXPECT_NE(most.find("do not fit in this process's memory"), std::string::npos) << most;
  const std::size_t too_many = std::size_t{1} << 44;
  std::string e = error_of([&] { sh::Channel<sh::Attrib4f> c(too_many); });
  EXPECT_NE(e.find("17592186044416 elements of f32x4 (281474976710656 bytes) do not fit"), std::string::npos) << e;
  EXPECT_NE(error_of([] { sh::Table2D<sh::Attrib4f> t(1 << 22, 1 << 22); }).find("do not fit in this process's memory"),
            std::string::npos);
}

TEST(HostMemory, MisalignedMemoryIsRefused) {
  alignas(8) unsigned char bytes[64] = {};
  ShHostMemoryPtr odd = new ShHostMemory(32, bytes + 2, SH_FLOAT);
  std::string e = error_of([&] { ShChannel<ShAttrib1f> c(odd, 4); });
  EXPECT_NE(e.find("not aligned to 4 bytes, as f32 values must be"), std::string::npos) << e;
  ShHostMemoryPtr half = new ShHostMemory(32, bytes + 4, SH_DOUBLE);
  e = error_of([&] { ShChannel<sh::Attrib1d> c(half, 2); });
  EXPECT_NE(e.find("not aligned to 8 bytes, as f64 values must be"), std::string::npos) << e;
  ShChannel<ShAttrib1f> floats(new ShHostMemory(32, bytes + 4, SH_FLOAT), 4);
  EXPECT_EQ(static_cast<void*>(floats.data()), bytes + 4) << "4-byte alignment is enough for floats";
}

TEST(HostMemory, ValueTypesAreNotConverted) {
  std::vector<std::int32_t> ints(4);
  ShHostMemoryPtr memory = new ShHostMemory(16, ints.data(), SH_INT);
  std::string e = error_of([&] { ShChannel<ShAttrib1f> c(memory, 4); });
  EXPECT_NE(e.find("the memory holds i32 values; the elements are f32"), std::string::npos) << e;
  ShChannel<ShAttrib1i> i(memory, 4);
  ShChannel<sh::Attrib1b> b(memory, 4);  // bools are stored as int32
  EXPECT_EQ(i.memory(), b.memory());
}

TEST(HostMemory, NullMemoryAndNullDataAreRefused) {
  EXPECT_NE(error_of([] { ShChannel<ShAttrib1f> c(ShMemoryPtr(), 1); }).find("the memory pointer is null"),
            std::string::npos);
  EXPECT_NE(error_of([] { ShHostMemory m(8, nullptr, SH_FLOAT); }).find("host memory of 8 bytes wraps a null pointer"),
            std::string::npos);
}

TEST(HostMemory, TableTooSmallNamesTheTable) {
  std::vector<float> data(15);
  ShArray2D<ShAttrib1f> grid(4, 4);
  grid.name("grid");
  std::string e = error_of([&] { grid.memory(new ShHostMemory(data.size() * sizeof(float), data.data(), SH_FLOAT)); });
  EXPECT_NE(e.find("table 'grid' of f32 (4 x 4) on host memory: 16 elements need 64 bytes; the memory holds 60"),
            std::string::npos)
      << e;
  data.resize(16, 2.5f);
  grid.memory(new ShHostMemory(data.size() * sizeof(float), data.data(), SH_FLOAT));
  EXPECT_EQ(grid.memory()->data(), data.data());
}

TEST(HostMemory, FailedRebindLeavesTheChannelAsItWas) {
  std::vector<float> big(8, 1.f), small(2);
  ShChannel<ShAttrib1f> c(new ShHostMemory(32, big.data(), SH_FLOAT), 8);
  EXPECT_THROW(c.memory(new ShHostMemory(8, small.data(), SH_FLOAT), 8), sh::Error);
  EXPECT_EQ(c.data(), big.data());
  EXPECT_EQ(c.count(), 8u);
}

TEST(HostMemory, OutputOnMemoryTooSmallForTheStream) {
  ShProgram p = copy_program();
  std::vector<float> out(3);
  ShChannel<ShAttrib1f> in(std::vector<float>{1, 2, 3, 4, 5});
  ShChannel<ShAttrib1f> empty(new ShHostMemory(12, out.data(), SH_FLOAT), 0);
  std::string e = error_of([&] { sh::run(p, {in}, {empty}, sh::backend("interp")); });
  EXPECT_NE(e.find("5 elements need 20 bytes; the memory holds 12"), std::string::npos) << e;
  ShChannel<ShAttrib1f> short_output(new ShHostMemory(12, out.data(), SH_FLOAT), 3);
  e = error_of([&] { sh::run(p, {in}, {short_output}, sh::backend("interp")); });
  EXPECT_NE(e.find("output channel 0 holds 3 elements but the stream has 5"), std::string::npos) << e;
}

TEST(HostMemory, AnEmptyChannelHasNoMemoryAndStillTakesTheStreamsLength) {
  ShProgram p = copy_program();
  ShChannel<ShAttrib1f> in(std::vector<float>{1, 2, 3}), out;
  EXPECT_FALSE(out.memory());
  sh::run(p, {in}, {out}, sh::backend("interp"));
  ASSERT_EQ(out.count(), 3u);
  ASSERT_TRUE(out.memory());
  EXPECT_EQ(static_cast<const float*>(out.memory()->data())[2], 3.f);
}

TEST(HostMemory, PointersFromOneRawPointerShareOneCount) {
  ShHostMemory* raw = new ShHostMemory(16, SH_FLOAT);
  ShMemoryPtr a = raw;
  ShHostMemoryPtr b = raw;  // as Sh's intrusive count allowed
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.use_count(), 2);
  ShHostStoragePtr storage = a->hostStorage();
  EXPECT_EQ(storage.use_count(), 3);
  EXPECT_EQ(storage->length(), 16u);
  EXPECT_NE(error_of([&] { a->findStorage("opengl:texture"); }).find("only the storage \"host\""), std::string::npos);
}

TEST(HostMemory, OwnMemoryIsZeroedAndAligned) {
  ShMemoryPtr m = new ShHostMemory(20, SH_DOUBLE);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m->data()) % 64, 0u);
  const unsigned char* bytes = static_cast<const unsigned char*>(m->data());
  for (int k = 0; k < 20; ++k) EXPECT_EQ(bytes[k], 0) << k;
  EXPECT_EQ(m->value_type(), SH_DOUBLE);
}

// A kernel's batch of 16 floats at a multiple of 16 elements fills one
// cache line of the memory a channel or table owns: large blocks, which
// malloc places 16 bytes past a page's start, included.
TEST(HostMemory, ChannelsAndTablesOwnMemoryThatStartsACacheLine) {
  for (std::size_t count : {1u, 1000u, 1u << 22}) {
    sh::Channel<sh::Attrib1f> channel(count);
    sh::Table1D<sh::Attrib3f> table(static_cast<int>(count));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(channel.memory()->data()) % 64, 0u) << count;
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(table.memory()->data()) % 64, 0u) << count;
  }
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(sh::HostMemory(1u << 24).data()) % 64, 0u);
}

// Large blocks taken one after another start at places in their pages at
// least 512 bytes apart either way: a kernel that reads one while it
// writes the next then finds no load waiting on a store to the other.
TEST(HostMemory, LargeBlocksInTurnStartApartInTheirPages) {
  constexpr std::uintptr_t kPage = 4096, kApart = 512;
  std::vector<sh::Channel<sh::Attrib1f>> blocks;
  for (int k = 0; k < 9; ++k) blocks.emplace_back(std::size_t{1} << 16);
  auto place = [&](int k) { return reinterpret_cast<std::uintptr_t>(blocks[k].memory()->data()) % kPage; };
  for (int k = 0; k + 1 < 9; ++k) {
    std::uintptr_t ahead = (place(k + 1) + kPage - place(k)) % kPage;
    EXPECT_GE(ahead, kApart) << k;
    EXPECT_LE(ahead, kPage - kApart) << k;
    EXPECT_EQ(place(k) % 64, 0u) << k;
  }
}

// Storage that grows from small to large and back is freed as it was
// taken (the sanitizer build checks each pair).
TEST(HostMemory, StorageGrowsAcrossTheLargeBlocksSize) {
  sh::detail::Words words(8, 1);
  for (std::size_t n : {std::size_t{1} << 12, std::size_t{1} << 14, std::size_t{1} << 20, std::size_t{16}}) {
    words.resize(n, 2);
    words.shrink_to_fit();
    EXPECT_EQ(words.front(), 1u) << n;
    EXPECT_EQ(words.back(), n > 8 ? 2u : 1u) << n;
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(words.data()) % 64, 0u) << n;
  }
}

TEST(HostMemory, DirtyGivesANewerVersion) {
  ShMemoryPtr a = new ShHostMemory(4, SH_FLOAT), b = new ShHostMemory(4, SH_FLOAT);
  a->dirty();
  std::uint64_t first = a->version();
  b->dirty();
  a->dirty();
  EXPECT_GT(b->version(), first);
  EXPECT_GT(a->version(), b->version()) << "one counter for all memory, so versions never repeat";
}

}  // namespace
