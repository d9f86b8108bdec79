// Access to the shared test meshes beside the project (../shared/data).
//
// Tests call DEFORM_REQUIRE_SHARED_FILE(var, "leg/leg_1633.obj"): it declares `var` as the full
// path, or skips the test with a message when the file is absent. DEFORM_SHARED_DATA (environment)
// overrides the folder chosen at configure time.
#pragma once

#include <cstdlib>
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

}  // namespace deform::test_support

#define DEFORM_REQUIRE_SHARED_FILE(var, relative)                                         \
  const std::string var = ::deform::test_support::SharedDataFile(relative);               \
  if (!std::filesystem::exists(var)) {                                                    \
    GTEST_SKIP() << "shared data absent (" << var << "); skipping this shared-mesh test"; \
  }
