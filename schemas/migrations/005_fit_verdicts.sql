-- Version 5 (after 004: fits.std_errors_ols_json, fits.error_model_json).
-- * fits.part_number, fits.verdict_json: the part the fit was judged against and the verdict,
--   {"pass": bool, "failed": [{"limit", "value", "bound"}], "part", "checked"}
--   (station/parts/verdict.hpp). NULL: no part limits applied (and every fit stored before).
-- * fits.adev_floor_dph: minimum of the overlapping ADEV of the compensated 1 Hz record, deg/h
--   (compensation/adev_floor.hpp); NULL when not computed.
-- * run_slots.part_number, run_slots.part_limits_json: the part each slot named when the run
--   started and a snapshot of its limits (the part-file keys), so a later `station fit` judges
--   against what applied. NULL: no part.
ALTER TABLE fits ADD COLUMN part_number TEXT;
ALTER TABLE fits ADD COLUMN verdict_json TEXT;
ALTER TABLE fits ADD COLUMN adev_floor_dph REAL;
ALTER TABLE run_slots ADD COLUMN part_number TEXT;
ALTER TABLE run_slots ADD COLUMN part_limits_json TEXT;
