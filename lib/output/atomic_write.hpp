// Atomic output: write to a temporary file in the target's directory, fsync,
// then rename over the target, so a reader never sees a half-written file and
// an interrupted run leaves the old file intact. Also: whole-directory
// replacement (a campaign written into a temporary folder and renamed into
// place), clean-up of temporary files when the process is stopped by
// SIGINT/SIGTERM/SIGHUP, and the fault-injection hook the CI uses.
//
// Fault injection: when the environment variable UMBMARK_TEST_KILL_AT_RENAME
// is N >= 1, the process raises SIGTERM (or the signal named by
// UMBMARK_TEST_KILL_SIGNAL: TERM, INT or KILL) just before its N-th rename
// into place. Tests use it to check that every output is either complete old
// or complete new and that no temporary file remains.
#pragma once

#include <string>
#include <string_view>

namespace umbmark::io {

/// Writes `content` to `path` atomically. A symbolic link is never replaced:
/// the write goes through to the regular file it points to (a dangling link
/// creates its target). Refuses (InputError) a target that is, or links to, a
/// device, FIFO, socket or directory, and links into /dev or /proc (e.g.
/// /dev/stdout; use '-' for standard output). The new file keeps the old
/// file's permission bits. Throws InputError(path, reason) on failure; the
/// temporary file is removed on every error path. The temporary is named
/// ".NAME.tmp.PID.HOST.N"; leftovers of NAME from a process of this host
/// that no longer runs (SIGKILL) are deleted first (also for staging
/// directories).
void WriteFileAtomically(const std::string& path, std::string_view content);

/// Where WriteFileAtomically(path) would write: the final regular-file path
/// after following symbolic links. Throws InputError for targets it refuses
/// (see above). Used by OutputSet to compare outputs with inputs.
std::string ResolveOutputTarget(const std::string& path);

/// Creates a fresh, empty temporary directory next to `dir` (same parent, so
/// a rename can move it into place). Registered for clean-up on SIGINT/
/// SIGTERM/SIGHUP together with the files written into it by
/// WriteFileAtomically. Throws InputError when it cannot.
std::string MakeStagingDirectory(const std::string& dir);

/// Moves the finished staging directory `staging` to `dir` in one rename.
/// `dir` must not exist or be an empty directory, unless `replace` is true:
/// then a non-empty `dir` is exchanged with the staging folder in one atomic
/// step (renameat2 RENAME_EXCHANGE) and the old contents are deleted.
/// Throws InputError; on failure the staging directory is removed.
void CommitStagingDirectory(const std::string& staging, const std::string& dir, bool replace);

/// Creates a folder (and its missing parents) inside a staging directory,
/// registered for clean-up with it. Throws InputError.
void CreateStagedFolder(const std::string& path);

/// Removes a staging directory and everything in it (error paths).
void DiscardStagingDirectory(const std::string& staging) noexcept;

/// Installs SIGINT/SIGTERM/SIGHUP handlers that delete the temporary files
/// and staging directories still in flight, then let the signal end the
/// process as before. Apps call it once at start-up.
void InstallTemporaryFileCleanup();

}  // namespace umbmark::io
