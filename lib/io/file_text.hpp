// Internal to io/: the whole text of an input file for the CSV readers.
// Regular files are memory-mapped (read-only, pre-faulted), which for a large
// trajectory log saves the copy and the page faults of read() into a buffer
// (about 0.2 s per 500 MB); pipes, devices and empty files are read instead.
// Caveat of mapping: a file truncated by another process while it is being
// parsed can end the process with SIGBUS, as with any mmap-based reader.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace umbmark::io::detail {

class FileText {
 public:
  /// Throws InputError(path, reason) when the file cannot be opened or read.
  explicit FileText(const std::string& path);
  ~FileText();
  FileText(const FileText&) = delete;
  FileText& operator=(const FileText&) = delete;

  std::string_view view() const { return map_ != nullptr ? std::string_view(map_, size_) : owned_; }

 private:
  const char* map_ = nullptr;
  std::size_t size_ = 0;
  std::string owned_;
};

}  // namespace umbmark::io::detail
