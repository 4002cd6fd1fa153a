// The data model: vertex blocks, per-vertex fields, mesh building and mesh statistics, atomic
// writes and the text reader's error messages.

#include <gtest/gtest.h>

#include <OpenMesh/Core/System/omstream.hh>
#include <memory>
#include <thread>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/vertex_fields.h"
#include "io/atomic_write.h"
#include "io/text_reader.h"
#include "test_support.h"

namespace mvflow {
namespace {

using test::octahedron;
using test::torus;

TEST(Blocks, CoverTheRangeContiguouslyAndDependOnlyOnBlockSize) {
  const auto blocks = split_into_blocks(1003, 100);
  ASSERT_EQ(blocks.size(), 11u);
  std::uint32_t next = 0;
  for (const auto& b : blocks) {
    EXPECT_EQ(b.begin, next);
    EXPECT_GT(b.size(), 0u);
    next = b.end;
  }
  EXPECT_EQ(next, 1003u);
  EXPECT_EQ(blocks.back().size(), 3u);
  EXPECT_TRUE(split_into_blocks(0, 10).empty());
  EXPECT_THROW(split_into_blocks(10, 0), Error);
}

TEST(VertexFields, ResizeGivesOneEntryPerVertexAndViewSlots) {
  VertexFields fields;
  fields.resize(5, 3);
  EXPECT_EQ(fields.size(), 5u);
  EXPECT_EQ(fields.normal.size(), 5u);
  EXPECT_EQ(fields.visible_views.size(), 15u);
  EXPECT_EQ(fields.view_capacity, 3u);
}

TEST(MeshStats, OctahedronIsClosedGenusZero) {
  const Mesh mesh = build_mesh(octahedron(), "octahedron");
  const MeshStats s = compute_mesh_stats(mesh);
  EXPECT_EQ(s.vertices, 6u);
  EXPECT_EQ(s.faces, 8u);
  EXPECT_EQ(s.edges, 12u);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_EQ(s.genus, 0);
  EXPECT_EQ(s.components, 1u);
  EXPECT_TRUE(s.is_closed());
  EXPECT_TRUE(s.is_manifold());
  EXPECT_DOUBLE_EQ(s.shortest_edge, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(s.longest_edge, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(s.bounding_box.diagonal(), std::sqrt(12.0));
}

TEST(MeshStats, TorusHasGenusOne) {
  const MeshStats s = compute_mesh_stats(build_mesh(torus(12, 8), "torus"));
  EXPECT_EQ(s.euler_characteristic, 0);
  EXPECT_EQ(s.genus, 1);
  EXPECT_TRUE(s.is_closed());
}

TEST(MeshStats, OpenMeshCountsBoundaryLoops) {
  IndexedMesh m = octahedron();
  m.triangles.pop_back();  // one hole
  m.triangles.erase(m.triangles.begin());  // a second, separate hole
  const MeshStats s = compute_mesh_stats(build_mesh(m, "open"));
  EXPECT_EQ(s.boundary_edges, 6u);
  EXPECT_EQ(s.boundary_loops, 2u);
  EXPECT_EQ(s.genus, 0);
}

TEST(BuildMesh, NonManifoldFacesAreReportedNotFatal) {
  IndexedMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  // Three triangles on the edge (0,1): the third cannot be added to a manifold mesh.
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  MeshBuildReport report;
  const Mesh mesh = build_mesh(m, "fan.ply", &report);
  EXPECT_EQ(report.rejected_faces, 1u);
  ASSERT_EQ(report.first_rejected.size(), 1u);
  EXPECT_EQ(report.first_rejected[0], 2u);
  EXPECT_EQ(mesh.n_faces(), 2u);
}

TEST(BuildMesh, OutOfRangeIndexNamesTheFace) {
  IndexedMesh m = octahedron();
  m.triangles[3][1] = 17;
  try {
    build_mesh(m, "bad.off");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "bad.off: face 3: vertex index 17 out of range (mesh has 6 vertices)");
  }
}

TEST(BuildMesh, KeepsTexcoordsWithTheirCorners) {
  IndexedMesh m = octahedron();
  for (std::size_t f = 0; f < m.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) m.texcoords.emplace_back(static_cast<float>(m.triangles[f][c]), static_cast<float>(f));
  const Mesh mesh = build_mesh(m, "uv");
  ASSERT_EQ(mesh.texcoords.size(), 24u);
  int corner = 0;
  for (auto f : mesh.topology.faces())
    for (auto v : mesh.topology.fv_range(f)) {
      EXPECT_EQ(mesh.texcoords[corner].x(), static_cast<float>(v.idx()));
      EXPECT_EQ(mesh.texcoords[corner].y(), static_cast<float>(f.idx()));
      ++corner;
    }
  // And back to the flat form unchanged.
  const IndexedMesh back = to_indexed(mesh);
  for (std::size_t f = 0; f < back.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back.texcoords[3 * f + c].x(), static_cast<float>(back.triangles[f][c]));
}

TEST(QuietOpenMesh, StreamsStayOffWhileAnyLivesAndComeBackAsTheHostHadThem) {
  // The host logs through OpenMesh's omlog but keeps omout off.
  omlog().enable();
  omout().disable();
  // Out of order, as two threads' instances can end: the first made is not the last gone.
  auto first = std::make_unique<QuietOpenMesh>();
  auto second = std::make_unique<QuietOpenMesh>();
  EXPECT_FALSE(omlog().is_enabled());
  first.reset();
  EXPECT_FALSE(omlog().is_enabled()) << "on again while an instance still lives";
  EXPECT_FALSE(omerr().is_enabled());
  second.reset();
  EXPECT_TRUE(omlog().is_enabled()) << "the host's stream left off";
  EXPECT_FALSE(omout().is_enabled()) << "a stream the host had off turned on";
  // Many threads at once (mesh reads in parallel jobs): the host's state comes back.
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([] {
      for (int i = 0; i < 2000; ++i) {
        const QuietOpenMesh quiet;
        EXPECT_FALSE(omlog().is_enabled());
      }
    });
  for (std::thread& thread : threads) thread.join();
  EXPECT_TRUE(omlog().is_enabled());
  EXPECT_FALSE(omout().is_enabled());
  omout().enable();
}

TEST(AtomicWrite, ExceptionLeavesDestinationAndNoTemporary) {
  test::ScratchFolder folder;
  const auto file = folder / "out.txt";
  test::write_text(file, "old");
  EXPECT_THROW(io::write_atomically(file, false,
                                    [](std::ostream& out) {
                                      out << "half";
                                      throw InputError("boom");
                                    }),
               InputError);
  EXPECT_EQ(test::read_text(file), "old");
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(folder.path())) ++entries;
  EXPECT_EQ(entries, 1);
  io::write_atomically(file, false, [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(test::read_text(file), "new");
}

TEST(TextReader, ErrorsNameFileLineAndExpectation) {
  test::ScratchFolder folder;
  test::write_text(folder / "numbers.txt", "# comment\n\n1.5 2\n3 abc\n4 nan\n");
  io::TextReader reader(folder / "numbers.txt");
  ASSERT_TRUE(reader.next_content_line());
  EXPECT_EQ(reader.line_number(), 3u);
  ASSERT_TRUE(reader.next_content_line());
  auto tokens = io::split_whitespace(reader.line());
  try {
    io::parse_double(reader, tokens[1], "'y'");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("numbers.txt:4: expected a number for 'y', got 'abc'"), std::string::npos);
  }
  ASSERT_TRUE(reader.next_content_line());
  tokens = io::split_whitespace(reader.line());
  EXPECT_THROW(io::parse_double(reader, tokens[1], "'y'"), InputError);
  EXPECT_THROW(io::parse_double(reader, "inf", "'y'"), InputError);
  EXPECT_THROW(io::parse_double(reader, "1e999", "'y'"), InputError);
  EXPECT_DOUBLE_EQ(io::parse_double(reader, "+2.5e-3", "'y'"), 2.5e-3);
  EXPECT_FALSE(reader.next_content_line());
  EXPECT_THROW(reader.require_content_line("more"), InputError);
}

}  // namespace
}  // namespace mvflow
