-- Version 3.
-- * fits.std_ratio may be NULL: the ratio of the std after to the std before compensation is
--   undefined when the std before is at rounding level (a constant input has nothing to
--   improve; compensation/fit.hpp, Evaluation). Fits stored before with a std before of 0 had
--   an invented ratio of 0 ("100 % better"); they become NULL.
-- SQLite cannot drop NOT NULL in place: the table is rebuilt (the "generalized ALTER TABLE"
-- procedure, sqlite.org/lang_altertable.html section 7), as in migration 2.
CREATE TABLE fits_v3 (
  id                 INTEGER PRIMARY KEY,
  serial             TEXT NOT NULL,
  created_utc        TEXT NOT NULL,
  runs_json          TEXT NOT NULL,   -- run ids the fit used
  terms              TEXT NOT NULL,
  ref_temp_c         REAL NOT NULL,
  coefficients_json  TEXT NOT NULL,
  std_errors_json    TEXT NOT NULL,
  n_bins             INTEGER NOT NULL,
  r2                 REAL NOT NULL,
  residual_rms_dph   REAL NOT NULL,
  condition_number   REAL NOT NULL,
  std_before_dph     REAL NOT NULL,
  std_after_dph      REAL NOT NULL,
  std_ratio          REAL,            -- NULL: undefined (std before at rounding level)
  warnings_json      TEXT NOT NULL
);
INSERT INTO fits_v3 (id, serial, created_utc, runs_json, terms, ref_temp_c, coefficients_json,
                     std_errors_json, n_bins, r2, residual_rms_dph, condition_number,
                     std_before_dph, std_after_dph, std_ratio, warnings_json)
  SELECT id, serial, created_utc, runs_json, terms, ref_temp_c, coefficients_json,
         std_errors_json, n_bins, r2, residual_rms_dph, condition_number, std_before_dph,
         std_after_dph, CASE WHEN std_before_dph > 0 THEN std_ratio END, warnings_json
  FROM fits;
DROP TABLE fits;
ALTER TABLE fits_v3 RENAME TO fits;
CREATE INDEX fits_by_serial ON fits (serial, id);
