-- Version 11 (issue 35): the gyros belong to the run, not to the configuration. Each run's slot
-- row already holds its serial (and, from version 5, its part_number); gyro_source says where
-- they came from:
-- * 'start': given with the run (`run --slot N=SERIAL[,PART]`, the API's "slots", the live
--   page's start form: station/daemon/run_gyros.hpp);
-- * 'config': the configuration's default serial for that slot ([[slot]] serial, part).
-- NULL: stored before version 11 (every serial then came from the configuration). It travels to
-- the fleet with the slot (fleet schema version 5, station/fleet/fleet_tables.cpp).
ALTER TABLE run_slots ADD COLUMN gyro_source TEXT CHECK (gyro_source IN ('start', 'config'));
