// WriteFileAtomically / ReadWholeFile: round trip, replacement of an existing
// file, no temporary left behind, and refusal of non-regular targets.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/errors.hpp"
#include "output/atomic_write.hpp"
#include "formats/file_text.hpp"

namespace fs = std::filesystem;
using namespace umbmark;

namespace {

/// A fresh empty directory, removed on destruction.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string templ = (fs::temp_directory_path() / "umbmark_io_test_XXXXXX").string();
    REQUIRE(::mkdtemp(templ.data()) != nullptr);
    path = templ;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::size_t Entries() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(path), fs::directory_iterator()));
  }
};

}  // namespace

TEST_CASE("atomic write round trip and replacement", "[io][atomic]") {
  TempDir dir;
  const std::string target = (dir.path / "out.json").string();
  const std::string content = std::string("{\"a\": 1}\n") + std::string(1 << 20, 'x') + std::string(1, '\0') + "end";
  io::WriteFileAtomically(target, content);
  CHECK(io::ReadWholeFile(target) == content);
  io::WriteFileAtomically(target, "short");
  CHECK(io::ReadWholeFile(target) == "short");
  io::WriteFileAtomically(target, "");
  CHECK(io::ReadWholeFile(target).empty());
  // Only the target remains: the temporary file was renamed, not copied.
  CHECK(dir.Entries() == 1);
}

TEST_CASE("atomic write respects the umask for new files", "[io][atomic]") {
  TempDir dir;
  const std::string target = (dir.path / "m.txt").string();
  const mode_t old = ::umask(022);
  io::WriteFileAtomically(target, "x");
  ::umask(old);
  struct stat st {};
  REQUIRE(::stat(target.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0644);
}

TEST_CASE("atomic write refuses non-regular targets", "[io][atomic]") {
  TempDir dir;
  try {
    io::WriteFileAtomically("/dev/null", "x");
    FAIL("no error for /dev/null");
  } catch (const InputError& e) {
    CHECK(e.file() == "/dev/null");
    CHECK(e.line() == 0);
    CHECK_THAT(e.message(), Catch::Contains("not a regular file"));
  }
  CHECK_THROWS_WITH(io::WriteFileAtomically(dir.path.string(), "x"), Catch::Contains("is a directory"));
  const std::string fifo = (dir.path / "fifo").string();
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(io::WriteFileAtomically(fifo, "x"), Catch::Contains("not a regular file"));
  CHECK_THROWS_WITH(io::WriteFileAtomically((dir.path / "no/such/dir/f.txt").string(), "x"),
                    Catch::Contains("cannot create temporary file"));
  CHECK(dir.Entries() == 1);  // only the FIFO
}

TEST_CASE("ReadWholeFile faults", "[io][atomic]") {
  TempDir dir;
  CHECK_THROWS_AS(io::ReadWholeFile((dir.path / "missing.csv").string()), InputError);
  CHECK_THROWS_WITH(io::ReadWholeFile((dir.path / "missing.csv").string()),
                    Catch::Contains("missing.csv: cannot open: No such file or directory"));
  CHECK_THROWS_WITH(io::ReadWholeFile(dir.path.string()), Catch::Contains("is a directory"));
  // A non-regular readable file is read to its end.
  CHECK(io::ReadWholeFile("/dev/null").empty());
}
