// libFuzzer target: the skeleton readers (DEFORM_FUZZ_SKELETON_READER: ParseTgf or
// ParseSkeletonJson) on arbitrary bytes: a Status or a skeleton, never a crash or a sanitizer
// report.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/io/skeleton_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)deform::DEFORM_FUZZ_SKELETON_READER(
      std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
