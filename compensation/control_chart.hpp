// Shewhart control chart for individual values (X chart with the moving range of two), ISO
// 7870-2:2023 "Control charts — Part 2: Shewhart control charts", §7 and Table 3 (charts for
// individuals): centre line X̄, σ̂ = MR̄ / d₂ with MR_i = |x_i − x_{i−1}| and d₂ = 1.128 for
// subgroups of two, control limits X̄ ± 3σ̂. The moving range estimates the short-term
// (point-to-point) spread; a sustained shift shows as points beyond the limits (and raises σ̂
// only by the one range that spans it). Pure: values in time order in, the chart out.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace station::compensation {

/// d₂ for subgroups of n = 2: the expected range of two standard normal values, 2/√π
/// (ISO 7870-2:2023 Table 2: 1.128).
inline constexpr double kD2Pairs = 1.1283791670955126;

struct IndividualsChart {
  std::size_t n = 0;        ///< points
  double centre = 0;        ///< X̄
  double mr_bar = 0;        ///< mean moving range of consecutive points
  double sigma = 0;         ///< σ̂ = MR̄ / d₂
  double lcl = 0, ucl = 0;  ///< X̄ ∓ 3σ̂
  /// Indices of points beyond a control limit (none when σ̂ = 0: all values equal).
  std::vector<std::size_t> outside;
};

/// The chart of `x` (time order); empty with fewer than 2 points (no moving range). Non-finite
/// values are not allowed (the caller leaves out fits without the coefficient).
std::optional<IndividualsChart> individuals_chart(std::span<const double> x);

/// The same over points from several sources (`group[i]`: the station of point i): moving ranges
/// only between consecutive points of one group, pooled, so σ̂ is the point-to-point spread within
/// a source and an offset between sources — points of two stations interleaved in time — shows as
/// points beyond the limits instead of widening them (ISO 7870-2's rational subgroups: limits
/// from the variation within a subgroup, never between them). Empty without two points in one
/// group.
std::optional<IndividualsChart> individuals_chart(std::span<const double> x,
                                                  std::span<const int> group);

}  // namespace station::compensation
