#include "stages/flow/savitzky_golay.h"

#include <Eigen/Dense>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void SavitzkyGolayOptions::check() const {
  require_option(k >= 2 && k % 2 == 0, "k", k, "an even number >= 2");
  require_option(order >= 1 && order <= k, "order", order, "[1, k]");
}

std::vector<double> savitzky_golay_derivative_coefficients(int half_window, int order) {
  MVFLOW_CHECK(
      half_window >= 1 && half_window <= 10000 && order >= 1 && order <= 2 * half_window,
      "savitzky_golay_derivative_coefficients: need half_window >= 1 and 1 <= order <= 2*half_window");
  const int n = 2 * half_window + 1;
  // Fit p(x) = Σ_q a_q x^q at x = s / half_window ∈ [−1, 1] (monomials of s up to s^order would
  // make the columns differ by half_window^order in scale). Row 1 of the least-squares solution
  // operator gives a_1 = dp/dx(0) as a linear combination of the samples.
  Eigen::MatrixXd vandermonde(n, order + 1);
  for (int i = 0; i < n; ++i) {
    const double x = static_cast<double>(i - half_window) / half_window;
    double power = 1.0;
    for (int q = 0; q <= order; ++q, power *= x) vandermonde(i, q) = power;
  }
  const Eigen::MatrixXd solution =
      vandermonde.colPivHouseholderQr().solve(Eigen::MatrixXd::Identity(n, n));  // (order+1) × n
  std::vector<double> coefficients(n);
  // d/ds = (1/half_window) d/dx. The exact coefficients are odd in s; averaging the two halves
  // removes rounding asymmetry: c_{−s} = −c_s bit for bit and c_0 = 0.
  coefficients[half_window] = 0.0;
  for (int s = 1; s <= half_window; ++s) {
    const double odd = 0.5 * (solution(1, half_window + s) - solution(1, half_window - s)) / half_window;
    coefficients[half_window + s] = odd;
    coefficients[half_window - s] = -odd;
  }
  return coefficients;
}

}  // namespace mvflow
