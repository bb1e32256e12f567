-- Version 6 (issue 21): a fit becomes a gyro's calibration only when released, and a released
-- calibration is checked on runs it was not fitted on.
-- * releases: one row per release of a fit. The released calibration of a serial is its newest
--   release (highest id); an older release is superseded, never deleted. override_reason is
--   set when the fit's verdict failed (or it had none while its slot named a part) and the
--   release was forced; verdict_json is the fit's verdict as it stood at the release.
-- * verifications: a fit applied to an independent run (`station verify`): result_json holds
--   {"std_before_dph","std_after_dph","ratio","mean_residual_dph","drift_dph_per_c",
--   "drift_se_dph_per_c","adev_floor_dph","bins"}; verdict_json the verdict against the part's
--   verification limits (NULL: no limits applied).
CREATE TABLE releases (
  id               INTEGER PRIMARY KEY,
  fit_id           INTEGER NOT NULL REFERENCES fits(id),
  serial           TEXT NOT NULL,
  released_utc     TEXT NOT NULL,
  released_by      TEXT NOT NULL CHECK (length(released_by) > 0),
  note             TEXT NOT NULL DEFAULT '',
  override_reason  TEXT,
  verdict_json     TEXT
);
CREATE INDEX releases_by_serial ON releases (serial, id);

CREATE TABLE verifications (
  id            INTEGER PRIMARY KEY,
  fit_id        INTEGER NOT NULL REFERENCES fits(id),
  run_id        INTEGER NOT NULL REFERENCES runs(id),
  serial        TEXT NOT NULL,
  created_utc   TEXT NOT NULL,
  result_json   TEXT NOT NULL,
  part_number   TEXT,
  verdict_json  TEXT
);
CREATE INDEX verifications_by_run ON verifications (run_id, serial, id);
