-- Central (fleet) schema, version 4 (issue 34 point 7): which station holds a station name. The
-- first station to forward under a name binds it to its identity (its SQLite
-- station_identity.uuid, station migration 10); a station of another identity forwarding under
-- the same name is refused, nothing of it written, so two stations never merge into one history.
-- A station that moved to a new file (a new identity) is released by deleting its row here.
CREATE TABLE stations (
  name          text PRIMARY KEY,
  station_uuid  uuid NOT NULL,
  claimed_utc   timestamptz NOT NULL DEFAULT now()
);
