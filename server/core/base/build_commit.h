// The commit string, defined in the build directory's build_commit.cc, which build_commit.cmake
// writes at every build (only when it changed, so nothing recompiles while HEAD stays put).
// Include build_info.h instead: this declaration is the generated file's contract only.
#pragma once

namespace deform::internal {

extern const char kBuildCommit[];

}  // namespace deform::internal
