// Verdict and part columns (migration 5). Statements go through Store::cached: `fit --all`
// writes a verdict per serial.
#include "station/store/fit_verdicts.hpp"

namespace station {

void save_fit_verdict(Store& store, std::int64_t fit_id, const StoredVerdict& v) {
  auto st = store.cached(
      "UPDATE fits SET part_number = ?, verdict_json = ?, adev_floor_dph = ? WHERE id = ?");
  const auto text_or_null = [&st](int i, const std::optional<std::string>& s) {
    if (s)
      st->bind(i, *s);
    else
      st->bind_null(i);
  };
  text_or_null(1, v.part_number);
  text_or_null(2, v.verdict_json);
  st->bind(3, v.adev_floor_dph).bind(4, fit_id);
  st->step();
}

StoredVerdict load_fit_verdict(Store& store, std::int64_t fit_id) {
  auto st = store.cached("SELECT part_number, verdict_json, adev_floor_dph FROM fits WHERE id = ?");
  st->bind(1, fit_id);
  StoredVerdict v;
  if (!st->step()) return v;
  if (!st->column_is_null(0)) v.part_number = st->column_text(0);
  if (!st->column_is_null(1)) v.verdict_json = st->column_text(1);
  if (!st->column_is_null(2)) v.adev_floor_dph = st->column_double(2);
  return v;
}

void save_run_parts(Store& store, std::int64_t run_id, const std::vector<SlotPart>& parts) {
  auto st = store.cached(
      "UPDATE run_slots SET part_number = ?, part_limits_json = ? WHERE run_id = ? AND "
      "serial = ?");
  for (const auto& p : parts) {
    st->bind(1, p.part_number).bind(2, p.limits_json).bind(3, run_id).bind(4, p.serial);
    st->step();
    st->reset();
  }
}

std::optional<SlotPart> find_run_part(Store& store, const std::string& serial,
                                      const std::vector<std::int64_t>& runs) {
  auto st = store.cached(
      "SELECT part_number, part_limits_json FROM run_slots WHERE run_id = ? AND serial = ? AND "
      "part_number IS NOT NULL");
  std::optional<SlotPart> found;
  for (auto it = runs.rbegin(); it != runs.rend() && !found; ++it) {
    st->bind(1, *it).bind(2, serial);
    if (st->step()) found = SlotPart{serial, st->column_text(0), st->column_text(1)};
    st->reset();
  }
  return found;
}

}  // namespace station
