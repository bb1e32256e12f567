// Releases (migration 6): a fit becomes a gyro's calibration only when someone releases it. The
// released calibration of a serial is its newest release; an older one is superseded, never
// deleted. A fit whose verdict failed, or that has none while its slot names a part, is released
// only with an override reason, stored with the release.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"
#include "station/store/store.hpp"

namespace station {

/// One stored release.
struct ReleaseRow {
  std::int64_t id = 0, fit_id = 0;
  std::string serial, released_utc, released_by, note;
  std::optional<std::string> override_reason;
  std::optional<std::string> verdict_json;  ///< the fit's verdict at the release (NULL: none)
};

/// What a person asks for.
struct ReleaseRequest {
  std::int64_t fit_id = 0;
  std::string by, note;
  std::optional<std::string> override_reason;
};

/// The fit does not exist (HTTP 404).
struct FitNotFound : InputError {
  using InputError::InputError;
};
/// The release is refused: failed or missing verdict without an override, a fit the block
/// cannot carry, or the fit is already the released one (HTTP 409).
struct ReleaseRefused : InputError {
  using InputError::InputError;
};

/// Releases a fit: checks the request, stores the release and an event ('release', on the
/// newest run of the fit) in one transaction. Throws FitNotFound; ReleaseRefused (failed or
/// missing verdict without an override, an override where none is needed, an undeliverable
/// model, already released); InputError for a blank name or reason, or text the text rule
/// refuses (common/text_rule.hpp: kMaxPersonBytes for the name, kMaxNoteBytes for the others).
ReleaseRow release_fit(Store& store, const ReleaseRequest& req);

/// The released calibration of `serial` (its newest release); empty when none.
std::optional<ReleaseRow> current_release(Store& store, const std::string& serial);
/// Every release of `serial`, oldest first.
std::vector<ReleaseRow> releases_of(Store& store, const std::string& serial);
/// The newest release of fit `fit_id`; empty when it was never released.
std::optional<ReleaseRow> release_of_fit(Store& store, std::int64_t fit_id);

/// {"release_id", "fit_id", "serial", "released_utc", "by", "note", "override"} (override null
/// when none): the one JSON shape of a release (export, history, API).
nlohmann::json release_json(const ReleaseRow& r);

/// "released 2026-11-25T10:00:00Z by Ann (override: ...)" for people.
std::string release_text(const ReleaseRow& r);

}  // namespace station
