// Tests of the incomplete gamma function and chi-squared quantiles against tabulated values.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "compensation/chi_squared.hpp"

namespace station::compensation {
namespace {

struct QuantileCase {
  double p;
  double dof;
  double expected;
};

// Reference quantiles: the classic table values (e.g. A&S Table 26.8: chi2_{0.975}(10) = 20.4832,
// chi2_{0.025}(100) = 74.2219) carried to 15 digits with mpmath (30-digit arithmetic). 0.15866
// and 0.84134 are the one-sigma tails used for 68.3 % Allan-deviation intervals.
constexpr QuantileCase kCases[] = {
    {0.025, 1, 0.000982069117175256},
    {0.975, 1, 5.02388618731489},
    {0.15866, 1, 0.0400719342558921},
    {0.84134, 1, 1.98695142502033},
    {0.0005, 1, 3.92699133102922e-7},
    {0.9995, 1, 12.1156651463972},
    {0.025, 2, 0.0506356159685798},
    {0.975, 2, 7.37775890822787},
    {0.025, 10, 3.24697278023684},
    {0.975, 10, 20.4831773508074},
    {0.15866, 10, 5.68067764070353},
    {0.84134, 10, 14.3253946597081},
    {0.0005, 10, 1.26498208066439},
    {0.9995, 10, 31.4198125074002},
    {0.025, 100, 74.2219274749237},
    {0.975, 100, 129.561197185837},
    {0.15866, 100, 85.9055769909047},
    {0.84134, 100, 114.09496579792},
    {0.0005, 100, 59.8956579865643},
    {0.9995, 100, 153.166955081667},
    {0.025, 1000, 914.257153799259},
    {0.975, 1000, 1089.53091277491},
    {0.15866, 1000, 955.294428805596},
    {0.84134, 1000, 1044.70557818001},
    // Fractional degrees of freedom (edf of an Allan deviation is rarely an integer).
    {0.025, 2.5, 0.118622942100063},
    {0.975, 2.5, 8.39229526691297},
    {0.15866, 2.5, 0.574273766121051},
    {0.84134, 2.5, 4.449173452388},
    {0.0005, 2.5, 0.00505916742266516},
    {0.9995, 2.5, 16.5089195086958},
    {0.025, 0.5, 5.27320259125999e-7},
    {0.975, 0.5, 3.43323529996078},
    {0.15866, 0.5, 0.000855722149058508},
    {0.0005, 0.5, 8.43712236638995e-14},
};

TEST(ChiSquared, QuantilesMatchTableToTenDigits) {
  for (const QuantileCase& c : kCases) {
    const double got = chi_squared_quantile(c.p, c.dof);
    // The references carry 15 significant digits; the header promises ~1e-10 relative.
    EXPECT_NEAR(got / c.expected, 1.0, 1e-10) << "p=" << c.p << " dof=" << c.dof;
  }
}

TEST(ChiSquared, QuantileInvertsTheDistribution) {
  for (double dof : {0.7, 1.0, 3.3, 17.0, 250.5, 4.0e4, 6.0e5}) {
    for (double p : {1e-6, 0.001, 0.15866, 0.5, 0.84134, 0.999}) {
      const double x = chi_squared_quantile(p, dof);
      EXPECT_NEAR(regularized_gamma_p(0.5 * dof, 0.5 * x), p, 1e-9 * std::fmax(p, 1e-3))
          << "p=" << p << " dof=" << dof;
    }
  }
}

TEST(ChiSquared, QuantileEdgesAndBadInput) {
  EXPECT_EQ(chi_squared_quantile(0.0, 3.0), 0.0);
  EXPECT_TRUE(std::isinf(chi_squared_quantile(1.0, 3.0)));
  EXPECT_THROW(chi_squared_quantile(0.5, 0.0), std::domain_error);
  EXPECT_THROW(chi_squared_quantile(1.5, 2.0), std::domain_error);
  EXPECT_THROW(regularized_gamma_p(-1.0, 1.0), std::domain_error);
}

TEST(RegularizedGamma, ClosedFormsAndReferenceValues) {
  // P(1, x) = 1 - e^-x; P(1/2, x) = erf(sqrt(x)) (A&S 6.5.17 ... 6.5.18).
  for (double x : {1e-3, 0.5, 1.9, 2.1, 7.0, 40.0}) {
    EXPECT_NEAR(regularized_gamma_p(1.0, x), -std::expm1(-x), 1e-14) << x;
    EXPECT_NEAR(regularized_gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-14) << x;
  }
  // P(3, 2) = 1 - e^-2 (1 + 2 + 2) (A&S 6.5.13); the rest from mpmath at 30 digits.
  EXPECT_NEAR(regularized_gamma_p(3.0, 2.0), 1.0 - 5.0 * std::exp(-2.0), 1e-15);
  EXPECT_NEAR(regularized_gamma_p(50.0, 40.0), 0.070335066659394954, 1e-13);
  EXPECT_NEAR(regularized_gamma_p(2.5, 10.0), 0.99875026943696862, 1e-14);
  EXPECT_EQ(regularized_gamma_p(2.0, 0.0), 0.0);
}

}  // namespace
}  // namespace station::compensation
