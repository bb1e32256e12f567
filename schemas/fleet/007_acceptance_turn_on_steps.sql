-- Central (fleet) schema, version 7 (issue 36; station migration 15): every power_cycles step's
-- turn-on figures, one row per (run, serial, step) as the station's acceptance_turn_on_steps
-- holds them (version 6's acceptance_results carries the first step's only). They travel with
-- their run as its other child rows do (station/fleet/fleet_tables.cpp: Merge::replace_set): a
-- resend replaces the run's rows, a step or serial the station no longer has is deleted.
-- Columns as station migration 15 describes them; ok 0/1.
CREATE TABLE IF NOT EXISTS acceptance_turn_on_steps (
  run_uuid                 uuid NOT NULL,
  serial                   text NOT NULL,
  step_no                  bigint NOT NULL CHECK (step_no >= 1),
  step_index               bigint,
  label                    text,
  temp_c                   double precision,
  ok                       bigint NOT NULL CHECK (ok IN (0, 1)),
  error                    text,
  turn_ons                 bigint,
  repeatability_dph        double precision,
  repeatability_lower_dph  double precision,
  repeatability_upper_dph  double precision,
  max_warmup_s             double precision,
  PRIMARY KEY (run_uuid, serial, step_no)
);
CREATE INDEX IF NOT EXISTS acceptance_turn_on_steps_by_serial ON acceptance_turn_on_steps (serial);
