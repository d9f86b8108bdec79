# Sourced by the tests that check the build's commit (version_test.sh, service/metrics_scrape_test.sh).
#   expected_commit SOURCE_DIR   prints the commit a build of SOURCE_DIR at this moment carries, by
#                                the rule of server/core/base/build_commit.cmake: `git rev-parse
#                                --short HEAD` when SOURCE_DIR is the top of a git checkout,
#                                "unknown" otherwise. A program that prints another commit was built
#                                before HEAD moved: rebuild.
expected_commit() {
  local top
  if top=$(git -C "$1" rev-parse --show-toplevel 2>/dev/null) &&
    [ "$(cd "$top" && pwd -P)" = "$(cd "$1" && pwd -P)" ]; then
    git -C "$1" rev-parse --short HEAD
  else
    echo unknown
  fi
}
