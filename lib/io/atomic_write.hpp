// Atomic output: write to a temporary file in the target's directory, fsync,
// then rename over the target, so a reader never sees a half-written file and
// an interrupted run leaves the old file intact.
#pragma once

#include <string>
#include <string_view>

namespace umbmark::io {

/// Writes `content` to `path` atomically. Refuses to write to anything that
/// exists and is not a regular file (device files such as /dev/null,
/// directories, FIFOs). Throws InputError(path, reason) on failure.
void WriteFileAtomically(const std::string& path, std::string_view content);

/// Reads a whole file. Throws InputError(path, reason) when it cannot.
std::string ReadWholeFile(const std::string& path);

}  // namespace umbmark::io
