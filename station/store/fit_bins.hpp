// What a fit reads of a serial's bins: the model data and the span of the same bins, in one read
// (issue 37: `fit --all` read them twice, the span by an aggregate query per run).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

struct FitBins {
  compensation::ModelData data;  ///< as Store::model_data
  /// As Store::bins_span: empty when a complete bin was stored before migration 8 (its ranges
  /// NULL) or there is none.
  std::optional<FitSpan> span;
};

/// The complete bins of `serial` over `runs`, in run order then time.
FitBins fit_bins(Store& store, const std::string& serial, const std::vector<std::int64_t>& runs);

}  // namespace station
