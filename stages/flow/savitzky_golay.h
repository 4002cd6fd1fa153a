#pragma once
// Savitzky–Golay first-derivative coefficients for the gradient of the photo consistency
// (thesis 5.3.3; SPEC §3).

#include <vector>

namespace mvflow {

//! The Savitzky–Golay parameters of the gradient ∇g (thesis 5.3.3, B.7; SPEC §3). The photo
//! stage samples g along each axis at X + s·Δx·e_a for s = −k/2..k/2 (k+1 points, the centre
//! shared between the axes: 3k+1 evaluations per vertex) and takes
//!   ∂g/∂a = (1/Δx) Σ_s c_s g(X + s·Δx·e_a)
//! with c_s = savitzky_golay_derivative_coefficients(k/2, order). The fitting neighbourhood is
//! Δ = k·Δx = e_min/2 (e_min = shortest edge of the current mesh, thesis B.7), so the spacing
//! is Δx = e_min/(2k) = e_min/40 for k = 20.
struct SavitzkyGolayOptions {
  //! k, the number of neighbours of the centre sample per axis (window k+1 points); even, ≥ 2,
  //! ≥ order. 20: the smallest neighbourhood that gave good results in the thesis (5.3.3).
  int k = 20;
  //! Order n of the fitted polynomial; ≥ 1. 4, as Press et al. recommend (thesis 5.3.3).
  int order = 4;

  //! k/2, the samples on each side of the centre.
  int half_window() const { return k / 2; }
  //! Δx = e_min / (2k): the sample spacing for a mesh whose shortest edge is \p shortest_edge.
  double sample_spacing(double shortest_edge) const { return shortest_edge / (2.0 * k); }
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Coefficients c_s, s = −half_window..half_window (element s + half_window), of the first
//! derivative at 0 of the least-squares polynomial of degree \p order through samples f(s) at
//! unit spacing: f'(0) ≈ Σ_s c_s f(s). Exact for polynomials of degree ≤ \p order;
//! Σ c_s = 0, Σ s·c_s = 1, and c_{−s} = −c_s exactly (c_0 = 0). Computed once at start-up (a QR
//! least-squares solve with Eigen, abscissae scaled to [−1, 1] for conditioning), not per vertex.
//! \param half_window Samples on each side of the centre, ≥ 1 (window 2·half_window + 1).
//! \param order       Polynomial degree, 1 ≤ order ≤ 2·half_window.
//! \return 2·half_window + 1 coefficients.
//! \throw Error if the parameters are out of range.
std::vector<double> savitzky_golay_derivative_coefficients(int half_window = 10, int order = 4);

}  // namespace mvflow
