-- Central (fleet) schema, version 1, PostgreSQL 15. Created and migrated by `station sync --init`
-- (station/fleet/fleet_schema.cpp); fleet_schema holds the version. A station refuses a server
-- whose version is older than its own (it would write columns the server lacks); a newer server
-- is accepted (migrations only add).
-- Rows are the stations' SQLite rows (schemas/migrations/) keyed by the uuid SQLite minted for
-- their run, fit, release or verification (migration 007), plus `station`: the name of the
-- station that recorded them. Child rows of a run carry its uuid and their natural key. No foreign
-- keys: a fit may arrive before the run it names (they travel independently) and a station's
-- rows must land whatever another station sent. fleet_id: an id across the fleet (local ids
-- collide between stations), assigned on first arrival and never changed. rev: the station's
-- revision of the item (fleet_outbox.changes); a row is only ever replaced by a higher one, so a
-- station file restored from a backup cannot write an older state over a newer one.
CREATE TABLE fleet_schema (
  version     integer NOT NULL,
  applied_utc timestamptz NOT NULL DEFAULT now()
);

CREATE TABLE runs (
  rev               bigint NOT NULL,
  fleet_id          bigint GENERATED ALWAYS AS IDENTITY UNIQUE,
  uuid              uuid PRIMARY KEY,
  station           text NOT NULL,
  local_id          bigint NOT NULL,
  started_utc       text NOT NULL,
  ended_utc         text,
  state             text NOT NULL,
  protocol_name     text NOT NULL,
  protocol_text     text NOT NULL,
  config_text       text NOT NULL,
  software_version  text NOT NULL,
  operator          text NOT NULL,
  sim_seed          bigint,
  step_index        bigint NOT NULL,
  step_started_s    double precision NOT NULL,
  t_s               double precision,
  recording         bigint NOT NULL,
  record_start_s    double precision,
  start_temp_c      double precision,
  t0_wall_s         double precision,
  resolved_json     text NOT NULL,
  received_utc      timestamptz NOT NULL DEFAULT now()
);
CREATE INDEX runs_by_station ON runs (station, local_id);

CREATE TABLE run_slots (
  run_uuid             uuid NOT NULL,
  slot                 bigint NOT NULL,
  node                 bigint NOT NULL,
  serial               text NOT NULL,
  pulse_weight_arcsec  double precision NOT NULL,
  axis                 text NOT NULL,
  earth_rate_dph       double precision NOT NULL,
  part_number          text,
  part_limits_json     text,
  PRIMARY KEY (run_uuid, slot)
);
CREATE INDEX run_slots_by_serial ON run_slots (serial);

CREATE TABLE bins (
  run_uuid      uuid NOT NULL,
  serial        text NOT NULL,
  t_start_s     double precision NOT NULL,
  n             bigint NOT NULL,
  rate_dph      double precision,
  bias_dph      double precision,
  temp_c        double precision,
  grad_c        double precision,
  dtdt_c_per_h  double precision,
  complete      bigint NOT NULL,
  PRIMARY KEY (run_uuid, serial, t_start_s)
);

CREATE TABLE events (
  run_uuid   uuid NOT NULL,
  local_id   bigint NOT NULL,
  t_s        double precision NOT NULL,
  wall_utc   text NOT NULL,
  severity   text NOT NULL,
  source     text NOT NULL,
  kind       text NOT NULL,
  message    text NOT NULL,
  data_json  text,
  PRIMARY KEY (run_uuid, local_id)
);

CREATE TABLE samples (
  run_uuid     uuid NOT NULL,
  serial       text NOT NULL,
  t_s          double precision NOT NULL,
  net_pulses   bigint,
  interval_s   double precision,
  rate_dph     double precision,
  temp_c       double precision,
  temp2_c      double precision,
  air_c        double precision,
  setpoint_c   double precision,
  flags        bigint NOT NULL,
  recording    bigint NOT NULL,
  PRIMARY KEY (run_uuid, serial, t_s)
);

CREATE TABLE fits (
  rev               bigint NOT NULL,
  fleet_id             bigint GENERATED ALWAYS AS IDENTITY UNIQUE,
  uuid                 uuid PRIMARY KEY,
  station              text NOT NULL,
  local_id             bigint NOT NULL,
  serial               text NOT NULL,
  created_utc          text NOT NULL,
  runs_json            text NOT NULL,   -- the station's local run ids
  run_uuids_json       text NOT NULL,   -- the same runs by uuid
  terms                text NOT NULL,
  ref_temp_c           double precision NOT NULL,
  coefficients_json    text NOT NULL,
  std_errors_json      text NOT NULL,
  n_bins               bigint NOT NULL,
  r2                   double precision NOT NULL,
  residual_rms_dph     double precision NOT NULL,
  condition_number     double precision NOT NULL,
  std_before_dph       double precision NOT NULL,
  std_after_dph        double precision NOT NULL,
  std_ratio            double precision,
  warnings_json        text NOT NULL,
  std_errors_ols_json  text,
  error_model_json     text,
  part_number          text,
  verdict_json         text,
  adev_floor_dph       double precision
);
CREATE INDEX fits_by_serial ON fits (serial, created_utc);
CREATE INDEX fits_by_part ON fits (part_number, created_utc);

CREATE TABLE releases (
  rev               bigint NOT NULL,
  uuid             uuid PRIMARY KEY,
  station          text NOT NULL,
  local_id         bigint NOT NULL,
  fit_uuid         uuid NOT NULL,
  serial           text NOT NULL,
  released_utc     text NOT NULL,
  released_by      text NOT NULL,
  note             text NOT NULL,
  override_reason  text,
  verdict_json     text
);
CREATE INDEX releases_by_serial ON releases (serial, released_utc);

CREATE TABLE verifications (
  rev               bigint NOT NULL,
  uuid          uuid PRIMARY KEY,
  station       text NOT NULL,
  local_id      bigint NOT NULL,
  fit_uuid      uuid NOT NULL,
  run_uuid      uuid NOT NULL,
  serial        text NOT NULL,
  created_utc   text NOT NULL,
  result_json   text NOT NULL,
  part_number   text,
  verdict_json  text
);
