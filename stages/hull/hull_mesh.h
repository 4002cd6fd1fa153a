#pragma once
// An initial mesh from silhouettes: the visual hull carved on a grid (stages/hull/visual_hull.h) and
// smoothed a little (stages/hull/scalar_grid.h), its surface by marching tetrahedra
// (stages/hull/iso_surface.h), the largest piece, remeshed isotropically onto that surface
// (stages/hull/isotropic_remeshing.h) to the target size, so that its edges have nearly one length —
// what the refiner's global split/collapse against the initial mesh's shortest edge needs.

#include <array>
#include <cstddef>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/camera.h"
#include "engine/model/mesh.h"
#include "stages/hull/iso_surface.h"
#include "stages/flow/silhouette.h"
#include "stages/hull/visual_hull.h"

namespace mvflow {

struct HullMeshOptions {
  VisualHullOptions carving;
  //! σ of the Gaussian blur of the carved field, in grid samples (0..100). The visual hull is
  //! an intersection of cones, full of creases and, with real silhouettes, of tunnels and
  //! bridges thinner than a voxel; 1 rounds the creases off and removes those (the Middlebury
  //! dino: genus 10 without, 0 with), which the remeshing needs to reach even edge lengths. A
  //! flat stretch of the surface does not move; a convex crease recedes by a fraction of σ.
  double smoothing = 1.0;
  IsoSurfaceOptions extraction;
  //! Target vertex count of the mesh (≥ 20); the result lands within a few per cent of it
  //! (the Middlebury hulls: 3–5 % below).
  //! 2500: the refiner's adaptive refinement adds detail where it is needed.
  int vertices = 2500;
  //! Rounds of isotropic remeshing (≥ 2): half with the edge length estimated from the area
  //! and the target count, half with that length scaled by the ratio of the count the first
  //! half reached to the target.
  //! 12: from the marching-tetrahedra mesh (tens of thousands of vertices) the count settles
  //! within about 5 rounds.
  int remeshing_iterations = 12;
  //! After the remeshing, the surface is cut along every loop of three edges that holds an edge
  //! shorter than this fraction of the target length (stages/hull/neck_cutting.h): a neck or handle
  //! thinner than the mesh resolution, where no remeshing can lengthen the edges (0..0.8;
  //! 0: never cut). 3 more rounds of remeshing follow each batch of cuts.
  double neck_edge = 0.5;
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

struct HullMeshResult {
  IndexedMesh mesh;                     //!< closed, manifold, one component, outward normals
  std::array<int, 3> grid_size{0, 0, 0};  //!< samples of the carving grid along x, y, z
  double grid_spacing = 0.0;            //!< world units
  std::size_t inside_samples = 0;       //!< grid samples kept by the carving
  std::size_t extracted_vertices = 0;   //!< of the iso-surface, all components
  std::size_t extracted_components = 0;
  std::size_t kept_vertices = 0;        //!< of the iso-surface's largest component
  std::size_t neck_cuts = 0;            //!< thin necks and handles cut away
  double target_edge = 0.0;             //!< the remeshing's final target edge length
  double seconds_carving = 0.0, seconds_extraction = 0.0, seconds_remeshing = 0.0;
};

//! The visual hull of \p silhouettes (one per camera) inside \p box as a mesh of about
//! options.vertices vertices. Parallel where carve_visual_hull is; the result does not depend on
//! the thread count.
//! \throw InputError for invalid options or inputs (see carve_visual_hull), or when nothing of
//!        the box survives the carving.
HullMeshResult make_hull_mesh(const std::vector<Camera>& cameras, const std::vector<Mask>& silhouettes,
                              const BoundingBox& box, const HullMeshOptions& options = {});

}  // namespace mvflow
