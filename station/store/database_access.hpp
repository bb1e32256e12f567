// How a process opens a station database file before SQLite does: the lock it takes on the file
// (common/database_lock.hpp) and, for a reader, how SQLite is to read it.
//
// A writer (OpenMode::create, existing) holds the file exclusively: every writing command, not
// only the daemons, so no two processes ever write it at once, whatever name each uses.
// A reader (OpenMode::read_only) never creates a file beside the database:
// - when another process writes it, the reader reads beside that writer through its WAL and
//   shared-memory index (they exist while it runs) with SQLITE_OPEN_READONLY;
// - when no process writes it, the reader holds a shared lock (no writer can start under it) and,
//   when no -wal or -shm lies beside it, reads it with `immutable=1` (sqlite.org/uri.html: no
//   locks, no -shm, no -wal; sqlite.org/wal.html "Read-Only Databases": otherwise a WAL database on
//   a read-only directory cannot be opened without its -shm), so it works on a read-only mount and
//   leaves nothing behind; a leftover -wal (a writer was killed) is read as it is, never ignored.
#pragma once

#include <optional>
#include <string>

#include "station/common/database_lock.hpp"

namespace station {

enum class OpenMode;

/// What opening a database file needs.
struct DatabaseAccess {
  std::optional<DatabaseHold> hold;  ///< none: ":memory:", a URI, a missing file, another's write
  bool immutable = false;            ///< read with `immutable=1` (readers only)
};

/// Takes what `mode` needs on `path` before SQLite opens it. Throws InputError when another
/// process writes the file (a writer asking), when a log beside another name of the file holds
/// writes (database_names.hpp), or when a writer uses another name than `path`'s (a reader asking).
DatabaseAccess claim_database_file(const std::string& path, OpenMode mode);

/// `path` as a SQLite URI filename read with immutable=1 (sqlite.org/uri.html: '%', '?' and '#'
/// escaped; the absolute path, so a name starting "//" cannot read as an authority).
std::string immutable_uri(const std::string& path);

}  // namespace station
