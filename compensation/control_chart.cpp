#include "compensation/control_chart.hpp"

#include <cmath>

namespace station::compensation {

std::optional<IndividualsChart> individuals_chart(std::span<const double> x) {
  if (x.size() < 2) return std::nullopt;
  IndividualsChart c;
  c.n = x.size();
  double sum = 0, mr = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sum += x[i];
    if (i > 0) mr += std::abs(x[i] - x[i - 1]);
  }
  c.centre = sum / static_cast<double>(x.size());
  c.mr_bar = mr / static_cast<double>(x.size() - 1);
  c.sigma = c.mr_bar / kD2Pairs;
  c.lcl = c.centre - 3 * c.sigma;
  c.ucl = c.centre + 3 * c.sigma;
  // σ̂ = 0 (every value the same): limits of zero width say nothing; no point is outside.
  if (c.sigma == 0) return c;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i] < c.lcl || x[i] > c.ucl) c.outside.push_back(i);
  return c;
}

}  // namespace station::compensation
