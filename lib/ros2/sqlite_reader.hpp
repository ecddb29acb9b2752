// Reader for rosbag2's SQLite3 storage (`.db3`), through libsqlite3, opened
// read-only. The tables rosbag2 writes (ROS 2 Foxy to Jazzy):
//   topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format
//          TEXT [, offered_qos_profiles TEXT] [, type_description_hash TEXT])
//   messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)
//   [metadata(...), schema(...)]   (newer distributions; not needed here)
// Only the columns every distribution has are read. Messages stream in
// timestamp order, one row in memory at a time. Reads are bounded by the
// file's size in memory (no message or sum of messages longer than the
// file: a generated zeroblob column is refused) and in time (SQLite's
// progress handler stops queries after a budget of steps per stored byte).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

struct sqlite3;

namespace umbmark::io::rosbag2 {

struct SqliteTopic {
  std::int64_t id = 0;
  std::string name, type, serialization_format;
  std::uint64_t count = 0;
  std::int64_t first_ns = 0, last_ns = 0;  ///< valid when count > 0
};

class SqliteBagFile {
 public:
  /// Opens read-only and reads the topics with their message counts. Throws
  /// InputError: not an SQLite database, not a rosbag2 database (the tables
  /// it has are listed), locked by another process.
  explicit SqliteBagFile(std::string path);
  ~SqliteBagFile();
  SqliteBagFile(const SqliteBagFile&) = delete;
  SqliteBagFile& operator=(const SqliteBagFile&) = delete;

  const std::vector<SqliteTopic>& topics() const { return topics_; }

  /// Calls fn(index into topics(), timestamp, data, size) for every message
  /// of the wanted topics (wanted[i] for topics()[i]), in timestamp order.
  void Stream(const std::vector<bool>& wanted,
              const std::function<void(std::size_t, std::int64_t, const std::uint8_t*, std::size_t)>& fn);

  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void Fail(const std::string& what) const;
  std::string path_;
  sqlite3* db_ = nullptr;
  std::uint64_t file_size_ = 0;
  std::uint64_t steps_ = 0, budget_ = 0;  ///< SQLite VM steps so far and allowed (progress handler)
  std::vector<SqliteTopic> topics_;
};

}  // namespace umbmark::io::rosbag2
