// Access to the shared test meshes beside the project (../shared/data).
//
// Tests call DEFORM_REQUIRE_SHARED_FILE(var, "leg/leg_1633.obj"): it declares `var` as the full
// path; when the file is absent the test fails, naming the path and the CMake cache variable
// DEFORM_SHARED_DATA_DIR that chose the folder, so that a CI which lost the data goes red instead
// of counting skips as passes. DEFORM_SHARED_DATA (environment) overrides the folder chosen at
// configure time. A developer without the data may set DEFORM_ALLOW_MISSING_SHARED_DATA=1 to skip
// those tests instead; CI never does, and scripts/run-ctest.sh fails a run with skipped tests.
#pragma once

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

namespace deform::test_support {

inline std::string SharedDataDir() {
  if (const char* env = std::getenv("DEFORM_SHARED_DATA")) return env;
  return DEFORM_SHARED_DATA_DIR;
}

inline std::string SharedDataFile(const std::string& relative) {
  return (std::filesystem::path(SharedDataDir()) / relative).string();
}

// True when DEFORM_ALLOW_MISSING_SHARED_DATA=1: absent shared files skip the tests that need them.
inline bool MissingSharedDataAllowed() {
  const char* allow = std::getenv("DEFORM_ALLOW_MISSING_SHARED_DATA");
  return allow != nullptr && std::strcmp(allow, "1") == 0;
}

// Why a test cannot run without `path`, and how to point the build at the data.
inline std::string MissingSharedDataMessage(const std::string& path) {
  return "shared data absent: " + path +
         " does not exist. Configure with -DDEFORM_SHARED_DATA_DIR=<the shared data folder> "
         "(CMake cache variable; now " DEFORM_SHARED_DATA_DIR
         "), or set DEFORM_SHARED_DATA; DEFORM_ALLOW_MISSING_SHARED_DATA=1 skips such tests "
         "instead";
}

}  // namespace deform::test_support

#define DEFORM_REQUIRE_SHARED_FILE(var, relative)                            \
  const std::string var = ::deform::test_support::SharedDataFile(relative);  \
  if (!std::filesystem::exists(var)) {                                       \
    if (::deform::test_support::MissingSharedDataAllowed()) {                \
      GTEST_SKIP() << ::deform::test_support::MissingSharedDataMessage(var); \
    }                                                                        \
    GTEST_FAIL() << ::deform::test_support::MissingSharedDataMessage(var);   \
  }
