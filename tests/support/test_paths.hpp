// The paths of this build, defined in the generated umbmark_test_paths.cpp
// (CMakeLists.txt), force-included into every test. Tests use the macros UMBMARK_SOURCE_DIR,
// UMBMARK_SHARED_DATA_DIR and UMBMARK_EXE, which expand to these calls.
#pragma once

namespace umbmark_test {
const char* SourceDir();      // the source tree (data/, tests/data/)
const char* SharedDataDir();  // ../shared/data next to the source tree, when present
const char* UmbmarkExe();     // the umbmark binary of this build
}  // namespace umbmark_test

#define UMBMARK_SOURCE_DIR (::umbmark_test::SourceDir())
#define UMBMARK_SHARED_DATA_DIR (::umbmark_test::SharedDataDir())
#define UMBMARK_EXE (::umbmark_test::UmbmarkExe())
