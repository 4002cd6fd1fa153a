#pragma once
// The surface: an OpenMesh triangle mesh with double-precision points (connectivity plus
// positions), the attributes that files carry (colour, quality, texture coordinates), and the
// plain indexed form that readers and writers exchange.

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace mvflow {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

inline Eigen::Vector3d to_eigen(const OpenMesh::Vec3d& p) { return {p[0], p[1], p[2]}; }
inline OpenMesh::Vec3d to_openmesh(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

//! A triangle mesh as flat arrays: what every reader returns and every writer takes.
struct IndexedMesh {
  std::vector<Eigen::Vector3d> positions;             //!< #V
  std::vector<std::array<std::uint32_t, 3>> triangles;  //!< #F, counter-clockwise seen from outside
  std::vector<Eigen::Vector3f> colors;                //!< empty or #V, RGB in [0,1]
  std::vector<float> quality;                         //!< empty or #V (mvflow writes g here)
  std::vector<Eigen::Vector2f> texcoords;             //!< empty or 3·#F, per triangle corner
  std::string texture_file;                           //!< texture image name, empty if none

  bool has_colors() const { return !colors.empty(); }
  bool has_quality() const { return !quality.empty(); }
  bool has_texcoords() const { return !texcoords.empty(); }
  //! Throws InputError naming the element when sizes disagree, an index is out of range or a
  //! value is not finite. \p source names the file in the message.
  void validate(const std::string& source) const;
};

//! The working surface. Vertex ids are 0..n_vertices()-1 and index every per-vertex array.
struct Mesh {
  TriMesh topology;                        //!< connectivity and positions
  std::vector<Eigen::Vector3f> colors;     //!< empty or one per vertex
  std::vector<float> quality;              //!< empty or one per vertex
  std::vector<Eigen::Vector2f> texcoords;  //!< empty or 3 per face, in face-id order
  std::string texture_file;

  std::size_t n_vertices() const { return topology.n_vertices(); }
  std::size_t n_faces() const { return topology.n_faces(); }
  Eigen::Vector3d position(std::size_t vertex) const {
    return to_eigen(topology.point(TriMesh::VertexHandle(static_cast<int>(vertex))));
  }
};

//! What building a Mesh from an IndexedMesh had to leave out.
struct MeshBuildReport {
  std::size_t rejected_faces = 0;        //!< faces OpenMesh could not add (non-manifold)
  std::vector<std::size_t> first_rejected;  //!< indices of the first few rejected faces
};

//! Builds the OpenMesh surface; faces that would make it non-manifold are skipped and reported.
//! \throw InputError (via IndexedMesh::validate) for out-of-range indices or non-finite values.
Mesh build_mesh(const IndexedMesh& indexed, const std::string& source, MeshBuildReport* report = nullptr);

//! The flat form of \p mesh (vertex ids and face ids kept).
IndexedMesh to_indexed(const Mesh& mesh);

//! Vertex positions of \p mesh, #V, in vertex-id order.
std::vector<Eigen::Vector3d> positions_of(const TriMesh& mesh);
//! Moves every vertex of \p mesh to \p positions (positions_of's order).
//! \throw Error if the count differs from #V.
void set_positions(TriMesh& mesh, const std::vector<Eigen::Vector3d>& positions);
//! Triangles of \p mesh, #F, in face-id order, corners in OpenMesh's face-vertex order.
std::vector<std::array<std::uint32_t, 3>> triangles_of(const TriMesh& mesh);

//! Keeps OpenMesh's console messages (omerr, omlog, omout) quiet while any instance lives: mvflow
//! reports problems itself, with the file and element named. OpenMesh's streams are process-wide,
//! so the instances share one count under a lock: the first switches the streams off (noting how
//! the host had them), the last one gone restores them, in whatever order and from whatever
//! threads they end (a host's own OpenMesh logging is never left off, never raced).
class QuietOpenMesh {
 public:
  QuietOpenMesh();
  ~QuietOpenMesh();
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;
};

}  // namespace mvflow
