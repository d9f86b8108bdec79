#include "core/base/build_info.h"

#include <iostream>

#include "core/base/build_commit.h"

namespace deform {

std::string_view BuildVersion() { return DEFORM_VERSION; }

std::string_view BuildCommit() { return internal::kBuildCommit; }

std::string VersionLine(std::string_view program) {
  std::string line(program);
  line.append(" ").append(BuildVersion()).append(" (commit ").append(BuildCommit()).append(")");
  return line;
}

bool PrintVersionIfAsked(int argc, const char* const* argv, std::string_view program) {
  if (argc != 2 || std::string_view(argv[1]) != "--version") return false;
  std::cout << VersionLine(program) << "\n";
  return true;
}

}  // namespace deform
