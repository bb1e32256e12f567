-- Central (fleet) schema, version 5 (issue 35; station migration 11): where a run's gyro on a
-- slot came from. 'start': given with the run (`run --slot`, the API's "slots", the live page's
-- start form); 'config': the configuration's default serial for that slot; NULL: forwarded by a
-- station before its version 11, when every serial came from the configuration.
ALTER TABLE run_slots ADD COLUMN IF NOT EXISTS gyro_source text CHECK (gyro_source IN ('start', 'config'));
