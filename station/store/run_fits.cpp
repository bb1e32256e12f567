// Which fits belong to a run (run_fits.hpp).
#include "station/store/run_fits.hpp"

#include <algorithm>

namespace station {

std::vector<FitRecord> fits_of_run(Store& store, const std::string& serial, std::int64_t run_id) {
  auto st = store.db().prepare(
      "SELECT id FROM fits WHERE serial = ? AND EXISTS (SELECT 1 FROM json_each(fits.runs_json) "
      "WHERE json_each.value = ?) ORDER BY id");
  st.bind(1, serial).bind(2, run_id);
  std::vector<std::int64_t> ids;
  while (st.step()) ids.push_back(st.column_int(0));
  std::vector<FitRecord> out;
  for (const auto id : ids)
    if (auto f = store.find_fit(id)) out.push_back(std::move(*f));
  return out;
}

std::optional<std::size_t> own_fit_index(const std::vector<FitRecord>& fits, std::int64_t run_id) {
  const auto alone = std::find_if(fits.begin(), fits.end(), [&](const FitRecord& f) {
    return f.runs == std::vector<std::int64_t>{run_id};
  });
  if (alone != fits.end()) return static_cast<std::size_t>(alone - fits.begin());
  if (fits.empty()) return std::nullopt;
  return 0;
}

std::optional<FitRecord> own_fit_of_run(Store& store, const std::string& serial,
                                        std::int64_t run_id) {
  auto fits = fits_of_run(store, serial, run_id);
  const auto own = own_fit_index(fits, run_id);
  if (!own) return std::nullopt;
  return std::move(fits[*own]);
}

}  // namespace station
