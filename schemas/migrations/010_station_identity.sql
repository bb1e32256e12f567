-- Version 10 (issue 34 point 7): the station's identity, 128 random bits as 32 hex digits minted
-- once, when the file is made or migrated, and never changed (a backup restored or a file copied
-- keeps it: it is the same station's record). The fleet binds a [station] name to the identity
-- that first forwarded under it (central `stations`, schemas/fleet/004_stations.sql), so a second
-- station under a name another one holds is refused instead of merging into its history.
CREATE TABLE station_identity (
  id    INTEGER PRIMARY KEY CHECK (id = 1),
  uuid  TEXT NOT NULL
);
INSERT INTO station_identity (id, uuid) VALUES (1, lower(hex(randomblob(16))));
