// How a process opens a station database file before SQLite does: the lock a writer takes on the
// file (common/database_lock.hpp) and how a reader is to read it.
//
// A writer (OpenMode::create, existing) holds the file exclusively: every writing command, not
// only the daemons, so no two processes ever write it at once, whatever name each uses.
// A reader (OpenMode::read_only) takes no lock and leaves no file beside the database:
// - beside a writer (another process holds the lock, or a -wal or -shm lies beside the file: a
//   writer runs, or one was killed and its log must be read) it reads through the WAL with
//   SQLITE_OPEN_READONLY, as SQLite's WAL lets readers do;
// - with no writer about, on a file or directory it cannot write (a read-only mount), with
//   `immutable=1` (sqlite.org/uri.html; sqlite.org/wal.html "Read-Only Databases": a WAL database
//   there cannot be opened otherwise, its -shm cannot be made). Such a read takes no lock, so a
//   writer that begins after the choice (the daemon can write where the operator cannot) goes
//   unseen by SQLite: the file's stamp (FileStamp) is taken before reading and compared again
//   after the reads (Database::check_unchanged), and a change refuses the result ("retry");
// - with no writer about, elsewhere, with SQLITE_OPEN_READWRITE under PRAGMA query_only: SQLite
//   makes the -wal and -shm it reads through and, the last connection closing, removes them
//   (sqlite.org/wal.html: "When the last connection to a database closes, that connection does
//   a checkpoint and then deletes the WAL and its associated shared-memory file"); a
//   SQLITE_OPEN_READONLY connection cannot, and left them behind. query_only refuses every
//   change to the data (sqlite.org/pragma.html#pragma_query_only); the WAL it checkpoints at
//   close is empty, since it held no -wal when it opened and wrote nothing.
#pragma once

#include <optional>
#include <string>

#include "station/common/database_lock.hpp"

namespace station {

enum class OpenMode;

/// How SQLite is to open the file for a reader.
enum class ReadWay {
  beside_writer,  ///< SQLITE_OPEN_READONLY, through the writer's -wal and -shm
  immutable,      ///< `immutable=1`: no locks, no -wal, no -shm (a read-only directory)
  leave_nothing,  ///< SQLITE_OPEN_READWRITE + query_only: the last close removes -wal and -shm
};

/// What an `immutable=1` reader saw of the file before reading it: a writer that begins after the
/// choice (a daemon starting a run, sync, fit) changes one of these, and the reader's pages may
/// then be a mix of two states. The header's file change counter (bytes 24..27,
/// sqlite.org/fileformat2.html §1.3) and the database size in pages (28..31) move with every
/// commit that writes page 1; size, mtime and ctime with every write or checkpoint; a -wal or
/// -shm appears with any writer.
struct FileStamp {
  unsigned long long ino = 0;
  long long size_bytes = 0;
  long long mtime_ns = 0;
  long long ctime_ns = 0;
  std::string header;  ///< bytes 24..31 of the file
  bool logs = false;   ///< a -wal or -shm beside it
  bool operator==(const FileStamp&) const = default;
};

/// The stamp of `path` now (all zero when it cannot be read).
FileStamp stamp_of(const std::string& path);

/// What opening a database file needs.
struct DatabaseAccess {
  std::optional<DatabaseHold> hold;  ///< a writer's (none: ":memory:", a URI, a missing file)
  ReadWay read = ReadWay::beside_writer;
  std::optional<FileStamp> stamp;  ///< ReadWay::immutable: the file as it was before reading
};

/// Takes what `mode` needs on `path` before SQLite opens it. Throws InputError when another
/// process writes the file (a writer asking), when a log beside another name of the file holds
/// writes (database_names.hpp), or when a writer uses another name than `path`'s (a reader asking).
DatabaseAccess claim_database_file(const std::string& path, OpenMode mode);

/// `path` as a SQLite URI filename read with immutable=1 (sqlite.org/uri.html: '%', '?' and '#'
/// escaped; the absolute path, so a name starting "//" cannot read as an authority).
std::string immutable_uri(const std::string& path);

}  // namespace station
