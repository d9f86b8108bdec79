// Splitting a count of items into equal parts, one per thread.
#pragma once

#include <cstdint>
#include <utility>

namespace deform {

// Part `part` of `parts` (0 <= part < parts) of [0, count): [count part / parts,
// count (part + 1) / parts). The parts cover [0, count) in order without overlap and differ in
// size by at most one.
inline std::pair<int, int> EqualPart(int count, int part, int parts) {
  const auto at = [&](int i) {
    return static_cast<int>(static_cast<std::int64_t>(count) * i / parts);
  };
  return {at(part), at(part + 1)};
}

}  // namespace deform
