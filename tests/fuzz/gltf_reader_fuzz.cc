// libFuzzer target: ReadGltf (skinned glTF 2.0, .gltf JSON with data URIs or .glb) on arbitrary
// bytes: a Status or a rig, never a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/io/rig_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  deform::MeshLimits limits;
  limits.max_vertices = 20'000;
  limits.max_triangles = 40'000;
  (void)deform::ReadGltf(std::string_view(reinterpret_cast<const char*>(data), size), limits);
  return 0;
}
