-- Central (fleet) schema, version 6 (issue 36; station migrations 12 and 13): a run's acceptance
-- figures, one row per (run, serial) as the station's acceptance_results holds them. They travel
-- with their run (a child row of the run item, keyed by the run's uuid and the serial, like bins):
-- the station's outbox counts a write of them as a change of the run (station migration 13), and
-- a recomputation (`station fit --acceptance`) replaces the run's central rows, a serial no longer
-- computed deleted (fleet_tables.cpp: Merge::replace_set). The station is the run's
-- (runs.station). Columns as station migration 12 describes them; pass 0/1, NULL: not judged.
CREATE TABLE IF NOT EXISTS acceptance_results (
  run_uuid                         uuid NOT NULL,
  serial                           text NOT NULL,
  computed_utc                     text NOT NULL,
  part_number                      text,
  pass                             bigint CHECK (pass IN (0, 1)),
  sf_pulse_per_arcsec              double precision,
  sf_se_pulse_per_arcsec           double precision,
  sf_temp_c                        double precision,
  tc_ppm_per_c                     double precision,
  tc_se_ppm_per_c                  double precision,
  nonlinearity_max_ppm_fs          double precision,
  asymmetry_ppm                    double precision,
  asymmetry_se_ppm                 double precision,
  tilt_mrad                        double precision,
  tilt_se_mrad                     double precision,
  turn_on_repeatability_dph        double precision,
  turn_on_repeatability_lower_dph  double precision,
  turn_on_repeatability_upper_dph  double precision,
  max_warmup_s                     double precision,
  figures_json                     text NOT NULL,
  PRIMARY KEY (run_uuid, serial)
);
CREATE INDEX IF NOT EXISTS acceptance_results_by_serial ON acceptance_results (serial);
CREATE INDEX IF NOT EXISTS acceptance_results_by_part ON acceptance_results (part_number);
