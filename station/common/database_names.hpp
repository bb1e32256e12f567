// SQLite finds a database's write-ahead log, shared-memory index and rollback journal by the name
// it opens (NAME-wal, NAME-shm, NAME-journal; a symlink resolved first). Two names of one file (a
// hard link) are two logs: what one holds, the other name never sees, and a checkpoint through
// either overwrites the other's pages (sqlite.org/howtocorrupt.html, §2.5 "Multiple links to the
// same file"; sqlite.org/wal.html). A database is opened only by the name its log sits beside.
#pragma once

#include <optional>
#include <string>

namespace station {

/// The name SQLite opens `path` by: every symlink resolved (its -wal sits beside this name).
std::string sqlite_name(const std::string& path);

/// A log that sits beside another name of the file `path` names and holds something (a -wal with
/// frames past its 32-byte header, a non-empty -journal), searched in the directories of `path`
/// and of sqlite_name(path); nullopt when there is none.
std::optional<std::string> log_of_another_name(const std::string& path);

/// Throws InputError naming `path` and the other name when log_of_another_name finds one.
void refuse_log_of_another_name(const std::string& path);

/// For a writer: throws InputError when `path` has more names (hard links, st_nlink) than the
/// directories log_of_another_name searches hold, since a log beside one of those could not be
/// seen (SQLite: a database file whose link count is not 1 is undefined behaviour,
/// howtocorrupt.html §2.5).
void refuse_names_not_found(const std::string& path);

}  // namespace station
