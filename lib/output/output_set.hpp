// Output safety for one command, in one place: every file a command reads and
// every file or folder it will write is registered, and Check() refuses,
// before anything is written, an output that resolves to an input or to
// another output (after following symbolic links and comparing device and
// inode), a folder output that contains an input, and a non-empty output
// folder without --force. Writes then go through WriteFileAtomically.
//
// Adopting it in a command (apps/cmd_*.cpp):
//
//   io::OutputSet outs;
//   outs.AddInput(o.data_csv);                 // every file the command reads
//   outs.AddManifestInputs(manifest);          // a manifest and its experiment files
//   outs.AddOutput("--json", o.json.path);     // "" = not requested, "-" = stdout
//   outs.AddOutput("--report", o.report);
//   outs.Check();                              // throws before anything is written
//   ... compute ...
//   outs.Write(o.report, html);                // re-checks, then writes atomically
//
// One writer per output set: Check() also takes an exclusive lock on every
// output (file or folder) before anything is written, held until the
// OutputSet is destroyed (for the apps: until the process ends). A second
// umbmark writing any of the same outputs waits for it (up to
// UMBMARK_LOCK_WAIT_S seconds, default 60), then fails with InputError
// (exit 1) naming the output; so two imports or calibrates into the same
// place run one after the other and never leave a mix of their files. The
// locks are flock(2) locks on files named by a hash of the output's absolute
// path in $TMPDIR/umbmark-locks (nothing is added beside the outputs),
// removed by their holder when it is done; the kernel releases a lock when
// its process ends, however it ends (a SIGKILL leaves an unlocked empty file,
// reused and removed by the next writer).
//
// For outputs whose name is only known later (batch names such as
// out-run1.svg), Write() checks the name against the inputs and the outputs
// written so far before writing.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/runs.hpp"

namespace umbmark::io {

class OutputSet {
 public:
  /// A file the command reads. Missing files are ignored (the reader reports them).
  void AddInput(const std::string& path);
  /// The manifest itself and every experiment file it names.
  void AddManifestInputs(const std::string& manifest_path, const Manifest& manifest);
  /// A file output given by `flag` ("--json", ...). Empty path: not requested;
  /// "-": standard output (at most one output may use it).
  void AddOutput(const std::string& flag, const std::string& path);
  /// A folder output (e.g. `simulate --out`): it must not be or contain an
  /// input; `files` are the names written into it, compared with the other
  /// outputs. Without `force`, an existing non-empty folder is refused.
  void AddOutputDirectory(const std::string& flag, const std::string& dir, const std::vector<std::string>& files,
                          bool force);

  /// Throws InvalidOptions (exit 2) naming the flag and both paths for a
  /// collision or a non-empty folder, InputError (exit 1) for an output that
  /// cannot be a regular file (device, FIFO, directory, /dev/stdout). Then
  /// takes the writer locks of every output (see above; InputError when
  /// another process holds one longer than the wait).
  void Check();

  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();

  /// Checks `path` against the inputs and the other outputs, then writes it
  /// atomically (WriteFileAtomically). `path` "-" writes to stdout.
  void Write(const std::string& path, std::string_view content);

 private:
  struct Entry {
    std::string flag;    ///< "--json", or "input"
    std::string path;    ///< as the user gave it
    std::string target;  ///< after following links (outputs) / absolute (inputs)
  };
  void CheckOutput(const Entry& out, std::size_t self) const;
  /// Takes the writer lock of `path` (an absolute output path) unless held.
  void Lock(const std::string& flag, const std::string& path);
  struct HeldLock {
    std::string key;   ///< normalised output path
    std::string file;  ///< the lock file
    int fd = -1;
  };
  std::vector<HeldLock> locks_;
  std::vector<Entry> inputs_;
  std::vector<Entry> outputs_;
  struct Folder {
    std::string flag, path, absolute;
  };
  std::vector<Folder> folders_;
  std::vector<std::string> written_;
};

/// True when the two paths name the same file (same device and inode, or,
/// for files that do not exist yet, the same absolute normalised path).
bool SameFile(const std::string& a, const std::string& b);

/// Seconds a writer waits for another process's lock on one of its outputs
/// (UMBMARK_LOCK_WAIT_S, a number >= 0; default 60).
double LockWaitSeconds();

}  // namespace umbmark::io
