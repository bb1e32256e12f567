-- Version 14 (issue 37): the runs that recorded a serial, found by the serial. `station fit`,
-- `fit --all`, `report` and a release ask it for every serial (Store::runs_of_serial: "SELECT
-- DISTINCT run_id FROM run_slots WHERE serial = ? ORDER BY run_id"), and without an index each
-- asked by scanning the whole table (13 % of `fit --all` over 1,000 serials). The index holds
-- (serial, run_id), so that query reads only the index, already in run order.
CREATE INDEX run_slots_by_serial ON run_slots (serial, run_id);
