// Regression tests for the fuzzers' findings (README "Fuzzing", tests/fuzz/): each test holds the
// minimized input of one finding and checks that the reader now refuses it (or reads it) cleanly,
// with mvflow's InputError naming the file and where, without crashing or allocating for a count
// the file does not hold. This executable counts the largest single allocation (operator new is
// replaced below) so that "no allocation beyond the input" is checked, not only the error.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "engine/error.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "tests/test_support.h"

namespace {

std::atomic<std::size_t> largest_allocation{0};

}  // namespace

void* operator new(std::size_t size) {
  std::size_t seen = largest_allocation.load(std::memory_order_relaxed);
  while (size > seen && !largest_allocation.compare_exchange_weak(seen, size, std::memory_order_relaxed)) {
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace mvflow::io {
namespace {

namespace fs = std::filesystem;
using test::ScratchFolder;
using test::write_text;

//! Runs \p read and returns the message of the InputError it must throw; fails the test otherwise.
template <typename Read>
std::string input_error_of(Read&& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

//! The largest single allocation made while \p read ran (that it throws or not).
template <typename Read>
std::size_t largest_allocation_of(Read&& read) {
  largest_allocation = 0;
  try {
    read();
  } catch (const Error&) {
  }
  return largest_allocation.load();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// obj_fuzzer: an `mtllib` name longer than the file system allows (ENAMETOOLONG) made
// std::filesystem::exists throw filesystem_error out of read_obj; a library that cannot be opened
// only loses the texture name, whatever the reason.
TEST(FuzzRegression, ObjMaterialLibraryNameTooLong) {
  ScratchFolder folder;
  const fs::path file = folder / "mesh.obj";
  write_text(file, "mtllib " + std::string(5000, 'x') + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const IndexedMesh mesh = read_obj(file);
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_TRUE(mesh.texture_file.empty());
}

// The same filesystem_error, found by reading after the OBJ finding: an image name in a camera file
// that the file system refuses is not found, so load_scene reports the view and the image name.
TEST(FuzzRegression, ImageNameTooLong) {
  ScratchFolder folder;
  EXPECT_FALSE(find_image(folder.path(), std::string(5000, 'x') + ".png"));
  EXPECT_FALSE(find_image(folder.path(), "/" + std::string(5000, 'x') + ".png"));
}

// off_fuzzer: "OFF\n   215155252 3 2\n" (23 bytes) reserved room for 215 million vertices
// (malloc of 5.2 GB) before finding that the file holds none.
TEST(FuzzRegression, OffVertexCountBeyondTheFile) {
  ScratchFolder folder;
  const fs::path file = folder / "mesh.off";
  write_text(file, "OFF\n   215155252 3 2\n");
  const std::string message = input_error_of([&] { read_off(file); });
  EXPECT_TRUE(contains(message, file.string() + ":3: expected 215155252 vertices, file ends after 0")) << message;
  EXPECT_LT(largest_allocation_of([&] { read_off(file); }), 1u << 20);
  write_text(file, "OFF\n3 215155252 0\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_LT(largest_allocation_of([&] { read_off(file); }), 1u << 20);
}

// off_fuzzer: "\r\r\nC\nC" (a first line of a lone '\r' once the line ending is removed) was a
// content line to TextReader but held no token for split_whitespace, so read_off took the first
// token of an empty list (UBSan: reference binding to null pointer). Blank now, as in every reader.
TEST(FuzzRegression, OffLineOfCarriageReturns) {
  ScratchFolder folder;
  const fs::path file = folder / "mesh.off";
  write_text(file, "\r\r\nC\nC");
  const std::string message = input_error_of([&] { read_off(file); });
  EXPECT_TRUE(contains(message, file.string() + ":2:")) << message;
  write_text(file, "OFF\r\n\r\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n\v\r\r\n0 1 0\r\n3 0 1 2\r\n");
  EXPECT_EQ(read_off(file).triangles.size(), 1u);
}

// The same count in a PLY header (found by reading ply.cpp after the OFF finding: both reserved
// room for the header's count).
TEST(FuzzRegression, PlyElementCountBeyondTheFile) {
  ScratchFolder folder;
  const fs::path file = folder / "mesh.ply";
  for (const char* format : {"ascii", "binary_little_endian"}) {
    write_text(file, std::string("ply\nformat ") + format +
                         " 1.0\nelement vertex 215155252\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 215155252\nproperty list uchar int vertex_indices\nend_header\n");
    const std::string message = input_error_of([&] { read_ply(file); });
    EXPECT_TRUE(contains(message, file.string())) << message;
    EXPECT_LT(largest_allocation_of([&] { read_ply(file); }), 1u << 20) << format;
  }
}

}  // namespace
}  // namespace mvflow::io
