// A rosbag2 recording: a folder with metadata.yaml (its
// `relative_file_paths` list gives the storage files in order), a folder of
// .mcap/.db3 files without metadata.yaml (a recorder that was killed; files
// read in name order, with a warning), or a single .mcap or .db3 file.
// Topics are merged over the files by name; messages stream file by file.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace umbmark::io::rosbag2 {

struct TopicInfo {
  std::string name;
  std::string type;                  ///< e.g. sensor_msgs/msg/JointState
  std::string serialization_format;  ///< cdr
  std::uint64_t count = 0;
  /// Receive-time span of the topic's messages when the storage tells it
  /// (SQLite, or MCAP read through); else of the whole recording.
  std::int64_t first_ns = 0, last_ns = 0;
  /// Messages per second over the span (0 with fewer than two messages).
  double RateHz() const;
};

/// One message as stored; data is valid during the callback only.
struct BagMessage {
  std::size_t topic = 0;  ///< index into Bag::topics()
  std::int64_t log_time_ns = 0;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  const std::string* file = nullptr;  ///< storage file it came from
  /// MCAP: the record's byte offset in the file, or for a compressed
  /// chunk the chunk's; SQLite: 0.
  std::uint64_t offset = 0;
  bool compressed_chunk = false;  ///< then chunk_byte: the record's offset in the decompressed chunk
  std::uint64_t chunk_byte = 0;
};

class Bag {
 public:
  /// Opens the recording at `path` and reads its topic list (the MCAP
  /// summary, or one pass when a file has none). Throws InputError; notes
  /// (e.g. missing metadata.yaml) are appended to `warnings`.
  static Bag Open(const std::string& path, std::vector<std::string>& warnings);

  const std::string& path() const { return path_; }
  const std::vector<std::string>& files() const { return files_; }
  const std::vector<TopicInfo>& topics() const { return topics_; }
  std::optional<std::size_t> FindTopic(std::string_view name) const;

  /// Streams the messages of the topics with wanted[i], file by file in
  /// storage order (receive-time order within a file as stored).
  void Read(const std::vector<bool>& wanted, const std::function<void(const BagMessage&)>& fn) const;

 private:
  std::string path_;
  std::vector<std::string> files_;
  std::vector<TopicInfo> topics_;
  std::unordered_map<std::string, std::size_t> index_;  ///< topic name -> index (200,000 topics happen)
};

/// The storage files a metadata.yaml lists under relative_file_paths, in
/// order. Throws InputError (file, line) when the list is missing or empty.
std::vector<std::string> ReadMetadataFileList(const std::string& metadata_path);

}  // namespace umbmark::io::rosbag2
