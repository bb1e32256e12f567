-- Version 12 (issue 36): a run's acceptance figures, one row per (run, serial), written when the
-- run ends (station/acceptance/acceptance_record.hpp: run_acceptance judged against the part the
-- slot named) and again by `station fit --acceptance` (older runs, another part file). A new
-- computation replaces the run's rows: they are derived from the run's stored events and samples,
-- never measured data.
-- * figures_json: the serial's object exactly as acceptance_json and judge_acceptance give it
--   (ladders, sf_vs_temp, positions, turn_on, verdict; a figure not computed is {"ok": false,
--   "error": why}), rows in the run's slot order (rowid): what GET /api/runs/{id}/acceptance
--   serves.
-- * the columns: the figures people compare across runs (`station history`, the fleet), each
--   NULL where the run did not compute it. sf_*: the scale factor the part is held to, K at
--   sf_temp_c (the temperature model's reference, else the one ladder's mean temperature);
--   tc_*: its temperature coefficient; nonlinearity: the largest over the ladders; asymmetry and
--   tilt: the ladder's or positions' largest in magnitude, with its standard error; turn-on:
--   the repeatability (sigma) with its confidence interval, the longest warm-up.
-- * part_number, pass: the verdict's; NULL when the serial's part has no acceptance limits.
CREATE TABLE acceptance_results (
  run_id                           INTEGER NOT NULL REFERENCES runs(id),
  serial                           TEXT NOT NULL,
  computed_utc                     TEXT NOT NULL,
  part_number                      TEXT,
  pass                             INTEGER CHECK (pass IN (0, 1)),
  sf_pulse_per_arcsec              REAL,
  sf_se_pulse_per_arcsec           REAL,
  sf_temp_c                        REAL,
  tc_ppm_per_c                     REAL,
  tc_se_ppm_per_c                  REAL,
  nonlinearity_max_ppm_fs          REAL,
  asymmetry_ppm                    REAL,
  asymmetry_se_ppm                 REAL,
  tilt_mrad                        REAL,
  tilt_se_mrad                     REAL,
  turn_on_repeatability_dph        REAL,
  turn_on_repeatability_lower_dph  REAL,
  turn_on_repeatability_upper_dph  REAL,
  max_warmup_s                     REAL,
  figures_json                     TEXT NOT NULL,
  PRIMARY KEY (run_id, serial)
);
CREATE INDEX acceptance_results_by_serial ON acceptance_results (serial, run_id);
