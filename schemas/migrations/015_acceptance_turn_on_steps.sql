-- Version 15 (issue 36): every power_cycles step's turn-on figures, one row per (run, serial,
-- step). acceptance_results' turn_on_* and max_warmup_s columns hold the first step's (they stay
-- as they were); a protocol with turn-ons at cold and at hot has each block analysed on its own
-- (station/acceptance/acceptance_run.cpp: pooling two temperatures' biases would add a temperature
-- effect to the repeatability), each judged, and now each stored, read back by `history` and
-- forwarded to the fleet (fleet schema version 7).
-- * step_no: the step's place among the run's power_cycles steps, 1..n, in the protocol's order
--   (the serial's turn_on_steps array, or its one turn_on object as step 1).
-- * step_index (0-based, in the protocol), label, temp_c (sensor A's mean over the powered
--   windows): as acceptance_json gives them; NULL for a run's only step (its object carries none).
-- * ok: whether the step was computed; error: why not; the figures NULL when not computed.
-- Written with the serial's row (station/store/acceptance_results.cpp, one transaction) and
-- deleted with it (the foreign key cascades): a recomputation replaces both.
CREATE TABLE acceptance_turn_on_steps (
  run_id                   INTEGER NOT NULL,
  serial                   TEXT NOT NULL,
  step_no                  INTEGER NOT NULL CHECK (step_no >= 1),
  step_index               INTEGER,
  label                    TEXT,
  temp_c                   REAL,
  ok                       INTEGER NOT NULL CHECK (ok IN (0, 1)),
  error                    TEXT,
  turn_ons                 INTEGER,
  repeatability_dph        REAL,
  repeatability_lower_dph  REAL,
  repeatability_upper_dph  REAL,
  max_warmup_s             REAL,
  PRIMARY KEY (run_id, serial, step_no),
  FOREIGN KEY (run_id, serial) REFERENCES acceptance_results (run_id, serial) ON DELETE CASCADE
);
-- Every write is a change of the run item in the outbox (migration 013's rule for its parent).
CREATE TRIGGER outbox_turn_on_steps_insert AFTER INSERT ON acceptance_turn_on_steps BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_turn_on_steps_update AFTER UPDATE ON acceptance_turn_on_steps BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_turn_on_steps_delete AFTER DELETE ON acceptance_turn_on_steps BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', OLD.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
-- Rows stored before this migration: their steps taken from their stored figures (the rule of
-- acceptance_row in station/store/acceptance_results.cpp, which the tests hold this to); each
-- insert makes its run pending again, so a station that already forwarded them sends them once.
INSERT INTO acceptance_turn_on_steps (run_id, serial, step_no, step_index, label, temp_c, ok,
                                      error, turn_ons, repeatability_dph,
                                      repeatability_lower_dph, repeatability_upper_dph,
                                      max_warmup_s)
SELECT a.run_id, a.serial, CAST(s.key AS INTEGER) + 1,
       CASE WHEN json_type(s.value, '$.step_index') = 'integer'
            THEN json_extract(s.value, '$.step_index') END,
       CASE WHEN json_type(s.value, '$.label') = 'text' THEN json_extract(s.value, '$.label') END,
       CASE WHEN json_type(s.value, '$.temp_c') IN ('integer', 'real')
            THEN json_extract(s.value, '$.temp_c') END,
       coalesce(json_type(s.value, '$.ok') = 'true', 0),
       CASE WHEN json_type(s.value, '$.ok') = 'true' THEN NULL
            WHEN json_type(s.value, '$.error') = 'text' THEN json_extract(s.value, '$.error')
            ELSE 'not computed' END,
       CASE WHEN json_type(s.value, '$.ok') = 'true' AND json_type(s.value, '$.turn_ons') = 'integer'
            THEN json_extract(s.value, '$.turn_ons') END,
       CASE WHEN json_type(s.value, '$.ok') = 'true'
             AND json_type(s.value, '$.repeatability_dph') IN ('integer', 'real')
            THEN json_extract(s.value, '$.repeatability_dph') END,
       CASE WHEN json_type(s.value, '$.ok') = 'true'
             AND json_type(s.value, '$.repeatability_lower_dph') IN ('integer', 'real')
            THEN json_extract(s.value, '$.repeatability_lower_dph') END,
       CASE WHEN json_type(s.value, '$.ok') = 'true'
             AND json_type(s.value, '$.repeatability_upper_dph') IN ('integer', 'real')
            THEN json_extract(s.value, '$.repeatability_upper_dph') END,
       CASE WHEN json_type(s.value, '$.ok') = 'true'
             AND json_type(s.value, '$.max_warmup_s') IN ('integer', 'real')
            THEN json_extract(s.value, '$.max_warmup_s') END
FROM acceptance_results AS a,
     json_each(CASE WHEN json_valid(a.figures_json) THEN
                 CASE WHEN json_type(a.figures_json, '$.turn_on_steps') = 'array'
                      THEN json_extract(a.figures_json, '$.turn_on_steps')
                      WHEN json_type(a.figures_json, '$.turn_on') = 'object'
                      THEN '[' || json_extract(a.figures_json, '$.turn_on') || ']'
                      ELSE '[]' END
               ELSE '[]' END) AS s
WHERE s.type = 'object';  -- json_each's own type: s.value of a string element is its bare text
