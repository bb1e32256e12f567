-- Version 1: runs, gyros, raw 1 Hz samples, bins, fits, events.
-- Times: t_s is steady/simulated seconds since the run started; *_utc are ISO-8601 wall time.
CREATE TABLE runs (
  id               INTEGER PRIMARY KEY,
  started_utc      TEXT NOT NULL,
  ended_utc        TEXT,
  state            TEXT NOT NULL CHECK (state IN ('running', 'completed', 'stopped', 'aborted')),
  protocol_name    TEXT NOT NULL,
  protocol_text    TEXT NOT NULL,
  config_text      TEXT NOT NULL,
  software_version TEXT NOT NULL,
  station          TEXT NOT NULL,
  operator         TEXT NOT NULL DEFAULT '',
  sim_seed         INTEGER,             -- NULL on real hardware
  step_index       INTEGER NOT NULL DEFAULT 0,
  step_started_s   REAL NOT NULL DEFAULT 0,
  t_s              REAL NOT NULL DEFAULT 0,   -- last committed tick
  recording        INTEGER NOT NULL DEFAULT 0,
  record_start_s   REAL,
  start_temp_c     REAL,                -- chamber air at the first tick (for 'return to start')
  t0_wall_s        REAL                 -- CLOCK_REALTIME at t_s = 0: a resume continues at the real elapsed time
);

CREATE TABLE gyros (
  serial          TEXT PRIMARY KEY,
  first_seen_utc  TEXT NOT NULL
);

CREATE TABLE run_slots (
  run_id               INTEGER NOT NULL REFERENCES runs(id),
  slot                 INTEGER NOT NULL,
  node                 INTEGER NOT NULL,
  serial               TEXT NOT NULL REFERENCES gyros(serial),
  pulse_weight_arcsec  REAL NOT NULL,
  axis                 TEXT NOT NULL,
  earth_rate_dph       REAL NOT NULL,
  PRIMARY KEY (run_id, slot)
);

CREATE TABLE samples (
  run_id       INTEGER NOT NULL REFERENCES runs(id),
  serial       TEXT NOT NULL,
  t_s          REAL NOT NULL,
  net_pulses   INTEGER,        -- NULL when the latch was lost
  interval_s   REAL,
  rate_dph     REAL,
  temp_c       REAL,
  temp2_c      REAL,
  air_c        REAL,
  setpoint_c   REAL,
  flags        INTEGER NOT NULL DEFAULT 0,
  recording    INTEGER NOT NULL,
  PRIMARY KEY (run_id, serial, t_s)
) WITHOUT ROWID;

CREATE TABLE bins (
  run_id        INTEGER NOT NULL REFERENCES runs(id),
  serial        TEXT NOT NULL,
  t_start_s     REAL NOT NULL,
  n             INTEGER NOT NULL,
  rate_dph      REAL,
  bias_dph      REAL,
  temp_c        REAL,
  grad_c        REAL,
  dtdt_c_per_h  REAL,
  complete      INTEGER NOT NULL,
  PRIMARY KEY (run_id, serial, t_start_s)
) WITHOUT ROWID;

CREATE TABLE fits (
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
  std_ratio          REAL NOT NULL,
  warnings_json      TEXT NOT NULL
);
CREATE INDEX fits_by_serial ON fits (serial, id);

CREATE TABLE events (
  id         INTEGER PRIMARY KEY,
  run_id     INTEGER REFERENCES runs(id),
  t_s        REAL NOT NULL,
  wall_utc   TEXT NOT NULL,
  severity   TEXT NOT NULL CHECK (severity IN ('info', 'warn', 'error')),
  source     TEXT NOT NULL,
  kind       TEXT NOT NULL,
  message    TEXT NOT NULL
);
CREATE INDEX events_by_run ON events (run_id, id);
