#pragma once
// The speed where the background shows through (README, "Weakly seen regions"). In a region of
// implausibly high g (implausible_g_vertices, stages/flow/unobserved_displacement.h) no view sees
// the surface, so ∇g·N is noise: on t2's peanut waist the speed's sign flipped from vertex to
// vertex (±7 against a median of 0.6 inward), the step damping held the region at a fraction of
// its step, and it crept in over 100 and more iterations. Each such vertex's speed becomes the mean
// over its neighbourhood instead: the noise averages out, the region's common motion (the
// curvature term g·H, the pull of the surface around it) stays. The mean is of the speed vectors
// F·N (on a curved region it gains a part along the surface, which the tangential regularization
// evens out): a mean of F set along each vertex's own normal measured 1.003× that (32 scenes × 3
// runs, 5 better / 6 worse by > 3 %; README, "Weakly seen regions").

#include <cstddef>
#include <cstdint>
#include <span>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct ImplausibleSpeedOptions {
  //! Rounds of one-ring means: in each, an implausible vertex's speed becomes the mean of its own
  //! and its neighbours' speeds (the neighbours with a speed, as the previous round left them);
  //! the other vertices keep theirs. 0 = off (the thesis preset). 8: over the 32 synthetic scenes
  //! × 3 runs 0.972× the error, better by > 3 % on 10 (w4 0.765, the peanut 0.775, t2 0.842),
  //! worse on 1 (u7 +3.2 %); 4: 0.969× but the bumpy sphere +4.3 %; 2: 0.981× (README, "Weakly
  //! seen regions"). The refiner applies it only where the implausible-g rule applies
  //! (UnobservedDisplacementOptions::implausible_g_ratio > 0, the rims not fitted). [0, 16].
  int rings = 8;

  //! \throw OptionError naming the field, its value and its valid values.
  void check() const;
};

//! Replaces the speed of every vertex with \p implausible[v] != 0 by options.rings rounds of
//! one-ring means (ImplausibleSpeedOptions::rings) over the vertices with kSpeedDefined. Serial,
//! neighbours in the mesh's circulation order: the same bits for any blocks or threads.
//! \return the number of vertices whose speed was replaced (0 when rings is 0).
//! \throw Error if the flags are not sized for the fields or the fields not for the mesh.
std::size_t average_implausible_speeds(const TriMesh& mesh, std::span<const std::uint8_t> implausible,
                                       const ImplausibleSpeedOptions& options, VertexFields& fields);

}  // namespace mvflow
