#pragma once
// Synthetic scenes for the benchmarks, built in memory (rendering is never timed): the bumpy
// sphere of `mvflow synth` on a ring of cameras, its initial mesh decimated to a chosen vertex
// count, the images handed to the scene's image store (no decoding, no copy).

#include <cstddef>
#include <string>

#include "engine/model/mesh.h"
#include "engine/model/scene.h"
#include "stages/synth/synth_scene.h"

namespace mvflow::perf {

//! What a benchmark scene is made of.
struct SceneSpec {
  std::size_t vertices = 10000;  //!< initial mesh vertex count (decimation target)
  int views = 16;                //!< cameras on a ring (synth's default rig)
  int width = 640;               //!< image size in pixels
  int height = 480;
  int supersample = 1;           //!< N×N rays per pixel when rendering (synth's default is 2)
  double amplitude = 0.08;       //!< bump height of the object (0: a sphere of radius 1)
  double init_offset = 0.01;     //!< initial mesh: truth smoothed and pushed out by this × diagonal
  //! "10k/16/640x480" style name.
  std::string label() const;
  //! Parses "VERTICES/VIEWS/WIDTHxHEIGHT"; VERTICES may end in k (×1000).
  //! \throw InputError for anything else.
  static SceneSpec parse(const std::string& text);
};

struct BenchScene {
  SceneSpec spec;
  Scene scene;          //!< views, images (in the store), bounding box
  Mesh initial;         //!< the initial mesh (the truth itself is not kept: it would count in peak memory)
  double seconds = 0;   //!< how long rendering and decimation took
};

//! Renders the scene (TBB, all cores). The truth is the bumpy sphere at the smallest icosphere
//! level (≤ 7) with at least 1.6 × spec.vertices vertices.
BenchScene make_bench_scene(const SceneSpec& spec);

}  // namespace mvflow::perf
