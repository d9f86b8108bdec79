// libFuzzer target: the phantom "spec" (its vertex count, what a LoadMesh header's phantom
// source carries) from the first four bytes. Counts up to 5,000 are built; larger ones are only
// checked to be refused beyond the 2,000,000 limit (building them would take seconds).
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/io/phantom.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::int32_t vertices = 0;
  std::memcpy(&vertices, data, size < sizeof vertices ? size : sizeof vertices);
  if (vertices <= 5'000) {
    (void)deform::MakeKneePhantom(vertices);
  } else if (vertices > 2'000'000) {
    if (deform::MakeKneePhantom(vertices).ok()) __builtin_trap();
  }
  return 0;
}
