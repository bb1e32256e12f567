-- Version 13 (issue 36): a run's acceptance figures travel to the fleet with the run (fleet
-- schema version 6, station/fleet/fleet_tables.cpp). Their rows are written when the run ends and
-- replaced by `station fit --acceptance` (station/store/acceptance_results.cpp: a delete and the
-- inserts, in one transaction), so every write of them is a change of the run item in the outbox
-- (migration 007), as a run's bins are; the forwarder then sends the run's rows anew and deletes
-- the central rows the station no longer has. Runs whose figures were stored before this
-- migration are pending again once, so a station that already forwarded them sends their figures.
CREATE TRIGGER outbox_acceptance_insert AFTER INSERT ON acceptance_results BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_acceptance_update AFTER UPDATE ON acceptance_results BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', NEW.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
CREATE TRIGGER outbox_acceptance_delete AFTER DELETE ON acceptance_results BEGIN
  INSERT INTO fleet_outbox (item, local_id) VALUES ('run', OLD.run_id)
    ON CONFLICT (item, local_id) DO UPDATE SET changes = changes + 1, samples_done = 0; END;
UPDATE fleet_outbox SET changes = changes + 1, samples_done = 0
  WHERE item = 'run' AND local_id IN (SELECT run_id FROM acceptance_results);
