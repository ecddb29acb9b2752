// rosbag2 SQLite3 storage reader (see sqlite_reader.hpp).
#include "ros2/sqlite_reader.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <sqlite3.h>

#include "core/errors.hpp"

namespace umbmark::io::rosbag2 {

namespace {

// Finalizes a statement on every path out.
struct Statement {
  sqlite3_stmt* stmt = nullptr;
  ~Statement() { sqlite3_finalize(stmt); }
};

std::string Text(sqlite3_stmt* s, int col) {
  const unsigned char* t = sqlite3_column_text(s, col);
  return t ? reinterpret_cast<const char*>(t) : "";
}

/// The SQLite URI that opens `path` read-only without writing beside it.
std::string ReadOnlyUri(const std::string& path) {
  std::error_code ec;
  // A database in WAL mode (file header byte 18 = 2) makes even a read-only
  // connection create -shm/-wal files beside it. With no -wal file there is
  // nothing beyond the main file, so it is opened immutable: nothing is
  // written next to the input. Otherwise (rollback journal, or a live WAL)
  // the normal read-only open with locking applies.
  bool immutable = false;
  {
    std::ifstream f(path, std::ios::binary);
    char head[100] = {};
    if (f.read(head, sizeof(head)) && std::memcmp(head, "SQLite format 3", 16) == 0 && head[18] == 2 &&
        !std::filesystem::exists(path + "-wal", ec))
      immutable = true;
  }
  std::string uri = "file:";
  for (char c : std::filesystem::absolute(path, ec).string()) {
    if (c == '?' || c == '#' || c == '%') uri += fmt::format("%{:02x}", static_cast<unsigned char>(c));
    else uri += c;
  }
  uri += immutable ? "?mode=ro&immutable=1" : "?mode=ro";
  return uri;
}

}  // namespace

void SqliteBagFile::Fail(const std::string& what) const { throw InputError(path_, what); }

// Long because opening a bag read-only without writing beside it (WAL and
// rollback journals), checking the rosbag2 schema (Humble and Jazzy) and
// preparing the statements must all succeed before the handle is kept; any
// failure closes the handle on the way out (no leak on a throwing constructor).
SqliteBagFile::SqliteBagFile(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path_, ec)) Fail("not a regular file");
  const std::string uri = ReadOnlyUri(path_);
  // A constructor that throws runs no destructor, and sqlite3_open_v2 hands
  // out a handle even when it fails: close it on every throw below.
  struct CloseOnThrow {
    sqlite3*& db;
    bool armed = true;
    ~CloseOnThrow() {
      if (armed) {
        sqlite3_close(db);
        db = nullptr;
      }
    }
  } close_on_throw{db_};
  if (sqlite3_open_v2(uri.c_str(), &db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX | SQLITE_OPEN_URI, nullptr) != SQLITE_OK)
    Fail(fmt::format("cannot open as SQLite3: {}", db_ ? sqlite3_errmsg(db_) : "out of memory"));
  sqlite3_busy_timeout(db_, 0);
  file_size_ = static_cast<std::uint64_t>(std::filesystem::file_size(path_, ec));
  // Time bounded by the file's size: a real recording's queries run a few
  // hundred virtual-machine steps per stored byte at most.
  budget_ = 100000000ull + 2000ull * file_size_;
  sqlite3_limit(db_, SQLITE_LIMIT_LENGTH, static_cast<int>(std::min<std::uint64_t>(file_size_ + 1024, 1000000000ull)));
  sqlite3_progress_handler(
      db_, 10000,
      [](void* self) -> int {
        auto* me = static_cast<SqliteBagFile*>(self);
        me->steps_ += 10000;
        return me->steps_ > me->budget_ ? 1 : 0;
      },
      this);
  auto prepare = [&](Statement& st, const char* sql) {
    const int rc = sqlite3_prepare_v2(db_, sql, -1, &st.stmt, nullptr);
    if (rc == SQLITE_NOTADB) Fail("not an SQLite3 database (a rosbag2 .db3 file is one)");
    if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) Fail("the database is locked by another process (is the recorder still running?)");
    if (rc != SQLITE_OK) Fail(fmt::format("SQLite error: {}", sqlite3_errmsg(db_)));
  };
  auto step_error = [&](int rc) {
    if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) Fail("the database is locked by another process (is the recorder still running?)");
    if (rc == SQLITE_NOTADB) Fail("not an SQLite3 database (a rosbag2 .db3 file is one)");
    if (rc == SQLITE_CORRUPT) Fail(fmt::format("corrupt SQLite3 database: {}", sqlite3_errmsg(db_)));
    if (rc == SQLITE_INTERRUPT) Fail("reading the topics took far longer than a recording of this size can (a generated table?)");
    Fail(fmt::format("SQLite error: {}", sqlite3_errmsg(db_)));
  };

  // Which tables are there: a rosbag2 database has topics and messages.
  std::vector<std::string> tables;
  {
    Statement st;
    prepare(st, "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name");
    int rc;
    while ((rc = sqlite3_step(st.stmt)) == SQLITE_ROW) tables.push_back(Text(st.stmt, 0));
    if (rc != SQLITE_DONE) step_error(rc);
  }
  const bool has_topics = std::find(tables.begin(), tables.end(), "topics") != tables.end();
  const bool has_messages = std::find(tables.begin(), tables.end(), "messages") != tables.end();
  if (!has_topics || !has_messages) {
    Fail(fmt::format("not a rosbag2 database: it needs the tables 'topics' and 'messages', it has {}",
                     tables.empty() ? std::string("none") : fmt::format("{}", fmt::join(tables, ", "))));
  }
  {
    Statement st;
    prepare(st, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
    int rc;
    while ((rc = sqlite3_step(st.stmt)) == SQLITE_ROW) {
      SqliteTopic t;
      t.id = sqlite3_column_int64(st.stmt, 0);
      t.name = Text(st.stmt, 1);
      t.type = Text(st.stmt, 2);
      t.serialization_format = Text(st.stmt, 3);
      topics_.push_back(std::move(t));
    }
    if (rc != SQLITE_DONE) step_error(rc);
  }
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < topics_.size(); ++i) index[topics_[i].id] = i;
  {
    Statement st;
    prepare(st, "SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp) FROM messages GROUP BY topic_id");
    int rc;
    while ((rc = sqlite3_step(st.stmt)) == SQLITE_ROW) {
      const std::int64_t id = sqlite3_column_int64(st.stmt, 0);
      auto it = index.find(id);
      if (it == index.end()) Fail(fmt::format("messages refer to topic id {}, which is not in the topics table", id));
      auto& t = topics_[it->second];
      t.count = static_cast<std::uint64_t>(sqlite3_column_int64(st.stmt, 1));
      t.first_ns = sqlite3_column_int64(st.stmt, 2);
      t.last_ns = sqlite3_column_int64(st.stmt, 3);
    }
    if (rc != SQLITE_DONE) step_error(rc);
  }
  close_on_throw.armed = false;
}

SqliteBagFile::~SqliteBagFile() { sqlite3_close(db_); }

void SqliteBagFile::Stream(const std::vector<bool>& wanted,
                           const std::function<void(std::size_t, std::int64_t, const std::uint8_t*, std::size_t)>& fn) {
  std::string ids;
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (i >= wanted.size() || !wanted[i]) continue;
    index[topics_[i].id] = i;
    if (!ids.empty()) ids += ',';
    ids += std::to_string(topics_[i].id);
  }
  if (ids.empty()) return;
  // Sorting only the small columns keeps the sorter small whatever the
  // data column holds; each row's data is then fetched by rowid once its
  // length is known to fit: no message may be longer than the file, nor
  // all of them together (a real recording stores its bytes; a generated
  // column or a zeroblob does not), so memory and time stay bounded by the
  // file's size.
  const std::string sql = "SELECT rowid, topic_id, timestamp, length(data) FROM messages WHERE topic_id IN (" + ids +
                          ") ORDER BY timestamp, id";
  Statement st, fetch;
  if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st.stmt, nullptr) != SQLITE_OK ||
      sqlite3_prepare_v2(db_, "SELECT data FROM messages WHERE rowid = ?", -1, &fetch.stmt, nullptr) != SQLITE_OK)
    Fail(fmt::format("SQLite error: {}", sqlite3_errmsg(db_)));
  std::uint64_t total = 0;
  int rc;
  while ((rc = sqlite3_step(st.stmt)) == SQLITE_ROW) {
    const std::int64_t rowid = sqlite3_column_int64(st.stmt, 0);
    const std::size_t topic = index.at(sqlite3_column_int64(st.stmt, 1));
    const std::int64_t ts = sqlite3_column_int64(st.stmt, 2);
    const std::int64_t len = sqlite3_column_int64(st.stmt, 3);
    total += static_cast<std::uint64_t>(std::max<std::int64_t>(len, 0));
    if (len < 0 || static_cast<std::uint64_t>(len) > file_size_ || total > file_size_)
      Fail(fmt::format("messages row {} (topic {}): its data claims {} bytes, {} in all so far, in a file of {} bytes: the "
                       "data column is generated, not stored (not a rosbag2 recording)",
                       rowid, topics_[topic].name, len, total, file_size_));
    sqlite3_reset(fetch.stmt);
    sqlite3_bind_int64(fetch.stmt, 1, rowid);
    const int frc = sqlite3_step(fetch.stmt);
    if (frc != SQLITE_ROW) Fail(fmt::format("SQLite error while reading messages row {}: {}", rowid, sqlite3_errmsg(db_)));
    const void* blob = sqlite3_column_blob(fetch.stmt, 0);
    const int n = sqlite3_column_bytes(fetch.stmt, 0);
    fn(topic, ts, static_cast<const std::uint8_t*>(blob), static_cast<std::size_t>(n));
  }
  if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) Fail("the database is locked by another process (is the recorder still running?)");
  if (rc == SQLITE_INTERRUPT) Fail("reading the messages took far longer than a recording of this size can (a generated table?)");
  if (rc == SQLITE_TOOBIG)
    Fail(fmt::format("a message's data is larger than the whole file ({} bytes): the data column is generated, not stored "
                     "(not a rosbag2 recording)", file_size_));
  if (rc != SQLITE_DONE) Fail(fmt::format("SQLite error while reading messages: {}", sqlite3_errmsg(db_)));
}

}  // namespace umbmark::io::rosbag2
