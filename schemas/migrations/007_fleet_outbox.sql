-- Version 7 (issue 24): store and forward to a fleet's PostgreSQL (station/fleet/).
-- * runs, fits, releases, verifications get a uuid: 128 random bits as 32 hex digits, minted by
--   SQLite when the row is inserted (whoever inserts it) and never changed. Central rows are keyed
--   by it, so a resend, a restored backup or two stations forwarding at once can neither
--   duplicate nor overwrite another row (two stations' local ids collide, their uuids do not).
-- * fleet_outbox: one row per run, fit, release and verification. Triggers bump `changes` on
--   every local write that concerns it (a run's record, slots, bins and events; a fit's verdict);
--   the forwarder sets `acked` to the `changes` it read once PostgreSQL has committed all of it,
--   and sends `changes` as the central row's `rev`: the server keeps the highest, so a file
--   restored from a backup (its `changes` behind the server's `rev`) is held, never written over
--   what the server has (`held_reason`). Pending: acked < changes, or a run whose samples are
--   wanted and not all sent since its last change (samples_done = 0), unless held or refused
--   until retry_after_unix. Written for every station, configured for a fleet or not: a station
--   that joins a fleet later forwards its whole history.
ALTER TABLE runs ADD COLUMN uuid TEXT;
ALTER TABLE fits ADD COLUMN uuid TEXT;
ALTER TABLE releases ADD COLUMN uuid TEXT;
ALTER TABLE verifications ADD COLUMN uuid TEXT;
UPDATE runs SET uuid = lower(hex(randomblob(16)));
UPDATE fits SET uuid = lower(hex(randomblob(16)));
UPDATE releases SET uuid = lower(hex(randomblob(16)));
UPDATE verifications SET uuid = lower(hex(randomblob(16)));
CREATE UNIQUE INDEX runs_by_uuid ON runs (uuid);
CREATE UNIQUE INDEX fits_by_uuid ON fits (uuid);
CREATE UNIQUE INDEX releases_by_uuid ON releases (uuid);
CREATE UNIQUE INDEX verifications_by_uuid ON verifications (uuid);
CREATE TRIGGER runs_uuid AFTER INSERT ON runs WHEN NEW.uuid IS NULL BEGIN
  UPDATE runs SET uuid = lower(hex(randomblob(16))) WHERE id = NEW.id; END;
CREATE TRIGGER fits_uuid AFTER INSERT ON fits WHEN NEW.uuid IS NULL BEGIN
  UPDATE fits SET uuid = lower(hex(randomblob(16))) WHERE id = NEW.id; END;
CREATE TRIGGER releases_uuid AFTER INSERT ON releases WHEN NEW.uuid IS NULL BEGIN
  UPDATE releases SET uuid = lower(hex(randomblob(16))) WHERE id = NEW.id; END;
CREATE TRIGGER verifications_uuid AFTER INSERT ON verifications WHEN NEW.uuid IS NULL BEGIN
  UPDATE verifications SET uuid = lower(hex(randomblob(16))) WHERE id = NEW.id; END;

CREATE TABLE fleet_outbox (
  item               TEXT NOT NULL CHECK (item IN ('run', 'fit', 'release', 'verification')),
  local_id           INTEGER NOT NULL,
  changes            INTEGER NOT NULL DEFAULT 1,  -- bumped by the triggers below
  acked              INTEGER NOT NULL DEFAULT 0,  -- `changes` as PostgreSQL last committed it
  acked_utc          TEXT,
  events_acked_id    INTEGER,  -- runs: highest events.id PostgreSQL holds
  samples_acked_t_s  REAL,     -- runs: highest samples.t_s PostgreSQL holds
  samples_done       INTEGER NOT NULL DEFAULT 0,  -- runs: every sample sent since the last change
  last_error         TEXT,     -- the last refusal for this item (NULL after a success)
  refusals           INTEGER NOT NULL DEFAULT 0,  -- refusals in a row (the retry back-off)
  retry_after_unix   REAL,     -- a refused item waits until then (Unix s)
  held_reason        TEXT,     -- set: never forwarded again until `station sync --retry-held`
  PRIMARY KEY (item, local_id)
);
INSERT INTO fleet_outbox (item, local_id) SELECT 'run', id FROM runs;
INSERT INTO fleet_outbox (item, local_id) SELECT 'fit', id FROM fits;
INSERT INTO fleet_outbox (item, local_id) SELECT 'release', id FROM releases;
INSERT INTO fleet_outbox (item, local_id) SELECT 'verification', id FROM verifications;

CREATE TRIGGER outbox_run_insert AFTER INSERT ON runs BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_run_update AFTER UPDATE ON runs BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_slot_insert AFTER INSERT ON run_slots BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_slot_update AFTER UPDATE ON run_slots BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_bin_insert AFTER INSERT ON bins BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_bin_delete AFTER DELETE ON bins BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', OLD.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_event_insert AFTER INSERT ON events WHEN NEW.run_id IS NOT NULL BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_fit_insert AFTER INSERT ON fits BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('fit', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_fit_update AFTER UPDATE ON fits BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('fit', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_release_insert AFTER INSERT ON releases BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('release', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_release_update AFTER UPDATE ON releases BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('release', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_verification_insert AFTER INSERT ON verifications BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('verification', NEW.id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
