-- Version 2.
-- * runs may end 'incomplete': a slot lost more of its record window than the configured share
--   (link outages); its fits say so in their warnings.
-- * runs.resolved_json: the resolved meaning of every sample (per slot: node, serial, pulse
--   weight, axis, Earth rate; latitude, reference temperature, bin length), compared on resume.
-- * runs.t_s is the last committed tick, written with every tick; a resume continues strictly
--   after it.
-- * events.data_json: structured detail (an outage's start, end and ticks lost, ...).
-- SQLite cannot change a CHECK constraint in place: the table is rebuilt (the documented
-- "generalized ALTER TABLE" procedure, sqlite.org/lang_altertable.html section 7; the migration
-- runner turns foreign keys off around it and runs PRAGMA foreign_key_check before commit).
CREATE TABLE runs_v2 (
  id               INTEGER PRIMARY KEY,
  started_utc      TEXT NOT NULL,
  ended_utc        TEXT,
  state            TEXT NOT NULL
                   CHECK (state IN ('running', 'completed', 'incomplete', 'stopped', 'aborted')),
  protocol_name    TEXT NOT NULL,
  protocol_text    TEXT NOT NULL,
  config_text      TEXT NOT NULL,
  software_version TEXT NOT NULL,
  station          TEXT NOT NULL,
  operator         TEXT NOT NULL DEFAULT '',
  sim_seed         INTEGER,
  step_index       INTEGER NOT NULL DEFAULT 0,
  step_started_s   REAL NOT NULL DEFAULT 0,
  t_s              REAL,                -- last committed tick; NULL before the first
  recording        INTEGER NOT NULL DEFAULT 0,
  record_start_s   REAL,
  start_temp_c     REAL,
  t0_wall_s        REAL,
  resolved_json    TEXT NOT NULL DEFAULT '{}'
);
INSERT INTO runs_v2 (id, started_utc, ended_utc, state, protocol_name, protocol_text, config_text,
                     software_version, station, operator, sim_seed, step_index, step_started_s,
                     t_s, recording, record_start_s, start_temp_c, t0_wall_s)
  SELECT id, started_utc, ended_utc, state, protocol_name, protocol_text, config_text,
         software_version, station, operator, sim_seed, step_index, step_started_s,
         (SELECT MAX(s.t_s) FROM samples s WHERE s.run_id = runs.id), recording, record_start_s,
         start_temp_c, t0_wall_s
  FROM runs;
DROP TABLE runs;
ALTER TABLE runs_v2 RENAME TO runs;
ALTER TABLE events ADD COLUMN data_json TEXT;
