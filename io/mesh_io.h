#pragma once
// Mesh files: PLY (ASCII and binary), OBJ, OFF, STL and VRML 2.0 IndexedFaceSet.
// The format follows the file extension (case-insensitive): .ply .obj .off .stl .wrl/.vrml.
// Polygons with more than three corners are split into a fan of triangles on read.

#include <filesystem>

#include "engine/model/mesh.h"

namespace mvflow::io {

enum class MeshFormat { Ply, Obj, Off, Stl, Vrml };

//! \throw InputError when the extension is not one of the supported ones.
MeshFormat mesh_format_from_path(const std::filesystem::path& file);

struct MeshWriteOptions {
  bool binary = true;            //!< PLY and STL: binary (default) or ASCII
  bool write_colors = true;      //!< PLY, OFF: per-vertex colour when the mesh has it
  bool write_quality = true;     //!< PLY: per-vertex `quality` when the mesh has it
  bool write_texcoords = true;   //!< OBJ, VRML: texture coordinates when the mesh has them
};

//! Reads any supported mesh file. \throw IoError (cannot open), InputError (file:line or
//! element and what was expected), never returns garbage.
IndexedMesh read_mesh(const std::filesystem::path& file);
//! Writes through a temporary file and rename (io/atomic_write.h).
void write_mesh(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options = {});

//! read_mesh followed by build_mesh, plus: an empty mesh (no triangle) is an InputError.
Mesh load_mesh(const std::filesystem::path& file, MeshBuildReport* report = nullptr);

// The individual formats (same contracts as read_mesh / write_mesh).
IndexedMesh read_ply(const std::filesystem::path& file);
void write_ply(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options);
IndexedMesh read_obj(const std::filesystem::path& file);
void write_obj(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options);
IndexedMesh read_off(const std::filesystem::path& file);
void write_off(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options);
IndexedMesh read_stl(const std::filesystem::path& file);
void write_stl(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options);
IndexedMesh read_vrml(const std::filesystem::path& file);
void write_vrml(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options);

}  // namespace mvflow::io
