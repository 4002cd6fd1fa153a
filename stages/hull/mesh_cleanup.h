#pragma once
// Clean-up of extracted surfaces: keep the largest piece, measure the enclosed volume.

#include <cstddef>

#include "engine/model/mesh.h"

namespace mvflow {

//! The connected component of \p mesh (triangles joined through shared vertices) with the most
//! triangles; of equally large ones, the one holding the lowest triangle id. Vertices no kept
//! triangle uses are dropped; the rest keep their relative order, as do the triangles.
//! \param components when not null, receives the number of components of \p mesh.
IndexedMesh largest_component(const IndexedMesh& mesh, std::size_t* components = nullptr);

//! The signed volume enclosed by a closed mesh (divergence theorem): positive when its
//! triangles are counter-clockwise seen from outside (outward normals).
double enclosed_volume(const IndexedMesh& mesh);

}  // namespace mvflow
