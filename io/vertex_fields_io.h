#pragma once
// One iteration's per-vertex state as a binary little-endian PLY (`refine --dump-fields DIR`):
// the surface with, per vertex, what the flow computed there. Any PLY reader (numpy, MeshLab,
// Open3D) reads it; README "Formats" lists the properties. For diagnosing the flow vertex by
// vertex: where a region creeps, whose speed is noise, which vertices have no g (README
// "Convergence").

#include <filesystem>
#include <string>

#include "engine/model/iteration_vertex_fields.h"

namespace mvflow::io {

//! The file name of iteration \p iteration's dump in a --dump-fields folder: "iteration_0007.ply"
//! (zero-padded to four digits, so that the names of a run of up to 9999 iterations sort in order).
std::string vertex_fields_file_name(int iteration);

//! Writes \p state to \p file atomically (write_atomically): element vertex with double x, y, z,
//! nx, ny, nz, g, mean_curvature, grad_g_normal (∇g·N), speed_normal (the state's moving_speed),
//! damping (the step damping's scale, 1 with damping off), moved (the flow step's length), uchar
//! defined (VertexDefined bits), views (visible views, at most 255 counted), patch (PatchKind: 0
//! undecided, 1 image, 2 surface); then element face with the triangles. g, H and ∇g·N are NaN
//! where not defined (kPhotoDefined, kCurvatureDefined, kGradientDefined). Comments give the
//! iteration and Δt.
//! \throw Error if the state's arrays are not sized for its mesh; IoError if the file cannot be written.
void write_vertex_fields(const std::filesystem::path& file, const IterationVertexFields& state);

}  // namespace mvflow::io
