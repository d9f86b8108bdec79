// libFuzzer target: ReadSkinWeights in one format (DEFORM_FUZZ_WEIGHTS_FORMAT: kDmat, ASCII and
// binary, or kCsv) on arbitrary bytes, then normalized against a mesh and skeleton of the sizes it
// names (bounded): a Status or weights, never a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/io/skin_weights_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  deform::MeshLimits limits;
  limits.max_vertices = 20'000;
  const auto format = deform::SkinWeightsFormat::DEFORM_FUZZ_WEIGHTS_FORMAT;
  auto weights = deform::ReadSkinWeights(
      std::string_view(reinterpret_cast<const char*>(data), size), format, limits);
  if (weights.ok()) {
    deform::WidenSkinWeights(format, 8, 4, &*weights);
  }
  return 0;
}
