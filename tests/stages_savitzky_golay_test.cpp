// Savitzky–Golay first-derivative coefficients (SPEC §3): against Gram polynomials, published
// tables, the closed form for cubic/quartic fits, and exactness on polynomials.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/savitzky_golay.h"

namespace mvflow {
namespace {

// Independent method: Gram polynomials (Gorry, Anal. Chem. 62, 1990), long double.
// gram(i, m, k, s) is the s-th derivative of the k-th Gram polynomial over −m..m at i.
long double gram(int i, int m, int k, int s) {
  if (k <= 0) return (k == 0 && s == 0) ? 1.0L : 0.0L;
  const long double a = (4.0L * k - 2.0L) / (k * (2.0L * m - k + 1.0L));
  const long double b = ((k - 1.0L) * (2.0L * m + k)) / (k * (2.0L * m - k + 1.0L));
  return a * (i * gram(i, m, k - 1, s) + s * gram(i, m, k - 1, s - 1)) - b * gram(i, m, k - 2, s);
}

long double generalized_factorial(int a, int b) {
  long double product = 1.0L;
  for (int j = a - b + 1; j <= a; ++j) product *= j;
  return product;
}

// Weight of sample i for the first derivative at t = 0 of the degree-n fit over −m..m.
std::vector<long double> gram_coefficients(int m, int n) {
  std::vector<long double> c;
  for (int i = -m; i <= m; ++i) {
    long double sum = 0.0L;
    for (int k = 0; k <= n; ++k)
      sum += (2.0L * k + 1.0L) * generalized_factorial(2 * m, k) /
             generalized_factorial(2 * m + k + 1, k + 1) * gram(i, m, k, 0) * gram(0, m, k, 1);
    c.push_back(sum);
  }
  return c;
}

// Closed form of the cubic/quartic first-derivative coefficients for 2m+1 points (the
// algebraic expressions tabulated with the Savitzky–Golay convolution coefficients); checked
// against the published 7- and 9-point tables below before it is trusted at 21 points.
long double closed_form_quartic(int m, int i) {
  const long double mm = m, x = i;
  const long double numerator = 5.0L * (3 * mm * mm * mm * mm + 6 * mm * mm * mm - 3 * mm + 1) * x -
                                7.0L * (3 * mm * mm + 3 * mm - 1) * x * x * x;
  const long double denominator =
      (2 * mm + 3) * (2 * mm + 1) * (2 * mm - 1) * (mm + 2) * (mm + 1) * mm * (mm - 1) / 5.0L;
  return numerator / denominator;
}

TEST(SavitzkyGolay, MatchesGramPolynomials) {
  for (const auto& [half, order] :
       std::vector<std::pair<int, int>>{{10, 4}, {3, 4}, {4, 4}, {10, 2}, {5, 3}, {12, 6}, {2, 1}}) {
    const auto c = savitzky_golay_derivative_coefficients(half, order);
    const auto expected = gram_coefficients(half, order);
    ASSERT_EQ(c.size(), expected.size());
    double max_difference = 0.0;
    for (std::size_t i = 0; i < c.size(); ++i)
      max_difference = std::max(max_difference, static_cast<double>(std::abs(c[i] - expected[i])));
    EXPECT_LT(max_difference, 1e-12) << "half window " << half << " order " << order;
    if (half == 10 && order == 4)
      std::printf("[measured] window 21 quartic vs Gram polynomials: max |diff| %.3g\n", max_difference);
  }
}

TEST(SavitzkyGolay, MatchesPublishedTablesForSevenAndNinePoints) {
  const double seven[] = {22, -67, -58, 0, 58, 67, -22};                // / 252
  const double nine[] = {86, -142, -193, -126, 0, 126, 193, 142, -86};  // / 1188
  const auto c7 = savitzky_golay_derivative_coefficients(3, 4);
  const auto c9 = savitzky_golay_derivative_coefficients(4, 4);
  ASSERT_EQ(c7.size(), 7u);
  ASSERT_EQ(c9.size(), 9u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(c7[i], seven[i] / 252.0, 1e-14);
    EXPECT_NEAR(static_cast<double>(closed_form_quartic(3, i - 3)), seven[i] / 252.0, 1e-15);
  }
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(c9[i], nine[i] / 1188.0, 1e-14);
    EXPECT_NEAR(static_cast<double>(closed_form_quartic(4, i - 4)), nine[i] / 1188.0, 1e-15);
  }
  // The cubic fit has the same first-derivative coefficients as the quartic (odd symmetry).
  const auto cubic7 = savitzky_golay_derivative_coefficients(3, 3);
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(cubic7[i], seven[i] / 252.0, 1e-14);
}

TEST(SavitzkyGolay, MatchesTheClosedFormForTheThesisWindow) {
  const auto c = savitzky_golay_derivative_coefficients();  // k = 20: 21 points, quartic
  ASSERT_EQ(c.size(), 21u);
  for (int i = 0; i < 21; ++i)
    EXPECT_NEAR(c[i], static_cast<double>(closed_form_quartic(10, i - 10)), 1e-14) << i;
}

TEST(SavitzkyGolay, MomentsAndSymmetry) {
  const auto c = savitzky_golay_derivative_coefficients(10, 4);
  double sum = 0.0, first = 0.0;
  for (int s = -10; s <= 10; ++s) {
    sum += c[s + 10];
    first += s * c[s + 10];
    EXPECT_EQ(c[10 + s], -c[10 - s]);
  }
  EXPECT_NEAR(sum, 0.0, 1e-15);  // exactly 0 pairwise; the sequential sum rounds
  EXPECT_NEAR(first, 1.0, 1e-14);
}

TEST(SavitzkyGolay, DifferentiatesPolynomialsUpToTheOrderExactly) {
  // Sampling as the photo stage will: spacing Δx = e_min/40 around an arbitrary point.
  const SavitzkyGolayOptions options;
  const auto c = savitzky_golay_derivative_coefficients(options.half_window(), options.order);
  const double dx = options.sample_spacing(0.1), x0 = 0.37;
  const double a[] = {0.3, -1.7, 2.2, 0.9, -1.3, 0.8};
  for (int degree = 0; degree <= 5; ++degree) {
    auto f = [&](double x) {
      double value = 0.0;
      for (int q = degree; q >= 0; --q) value = value * (x - x0 + 0.05) + a[q];
      return value;
    };
    auto derivative = [&](double x) {
      double value = 0.0;
      for (int q = degree; q >= 1; --q) value = value * (x - x0 + 0.05) + q * a[q];
      return value;
    };
    double estimate = 0.0;
    for (int s = -options.half_window(); s <= options.half_window(); ++s)
      estimate += c[s + options.half_window()] * f(x0 + s * dx);
    estimate /= dx;
    if (degree <= 4) {
      EXPECT_NEAR(estimate, derivative(x0), 1e-10) << "degree " << degree;
    }
  }
  // Degree 5 at unit spacing: s^5 has derivative 0 at 0 but the quartic fit sees a slope.
  const auto unit = savitzky_golay_derivative_coefficients(10, 4);
  double slope = 0.0;
  for (int s = -10; s <= 10; ++s) slope += unit[s + 10] * std::pow(s, 5);
  std::printf("[measured] quartic window-21 derivative of s^5 at 0: %.6g (exact: 0)\n", slope);
  EXPECT_GT(std::abs(slope), 1.0);
}

TEST(SavitzkyGolay, OptionsAndArguments) {
  const SavitzkyGolayOptions options;
  EXPECT_NO_THROW(options.check());
  EXPECT_EQ(options.k, 20);
  EXPECT_EQ(options.order, 4);
  EXPECT_EQ(options.half_window(), 10);
  EXPECT_DOUBLE_EQ(options.sample_spacing(0.4), 0.01);             // e_min / 40
  EXPECT_DOUBLE_EQ(options.k * options.sample_spacing(0.4), 0.2);  // Δ = e_min / 2
  EXPECT_THROW((SavitzkyGolayOptions{.k = 21}).check(), OptionError);
  EXPECT_THROW((SavitzkyGolayOptions{.k = 2, .order = 4}).check(), OptionError);
  EXPECT_THROW((SavitzkyGolayOptions{.order = 0}).check(), OptionError);
  EXPECT_THROW(savitzky_golay_derivative_coefficients(0, 1), Error);
  EXPECT_THROW(savitzky_golay_derivative_coefficients(2, 5), Error);
  EXPECT_THROW(savitzky_golay_derivative_coefficients(3, 0), Error);
  EXPECT_EQ(savitzky_golay_derivative_coefficients(2, 4).size(), 5u);  // interpolating fit
}

}  // namespace
}  // namespace mvflow
