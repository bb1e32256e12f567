#include "compensation/control_chart.hpp"

#include <cmath>
#include <vector>

namespace station::compensation {

std::optional<IndividualsChart> individuals_chart(std::span<const double> x,
                                                  std::span<const int> group) {
  // The moving range of each point with the previous point of its own group.
  std::vector<std::optional<double>> last;
  double sum = 0, mr = 0;
  std::size_t ranges = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sum += x[i];
    const auto g = static_cast<std::size_t>(group[i]);
    if (g >= last.size()) last.resize(g + 1);
    if (last[g]) {
      mr += std::abs(x[i] - *last[g]);
      ++ranges;
    }
    last[g] = x[i];
  }
  if (ranges == 0) return std::nullopt;
  IndividualsChart c;
  c.n = x.size();
  c.centre = sum / static_cast<double>(x.size());
  c.mr_bar = mr / static_cast<double>(ranges);
  c.sigma = c.mr_bar / kD2Pairs;
  c.lcl = c.centre - 3 * c.sigma;
  c.ucl = c.centre + 3 * c.sigma;
  // σ̂ = 0 (every value the same): limits of zero width say nothing; no point is outside.
  if (c.sigma == 0) return c;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i] < c.lcl || x[i] > c.ucl) c.outside.push_back(i);
  return c;
}

std::optional<IndividualsChart> individuals_chart(std::span<const double> x) {
  const std::vector<int> one(x.size(), 0);
  return individuals_chart(x, one);
}

}  // namespace station::compensation
