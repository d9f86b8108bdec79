// libFuzzer target: ReadDeclaredMeshSize (the service's admission before parsing) and ReadMesh on
// arbitrary bytes in one format (DEFORM_FUZZ_MESH_FORMAT, one executable per format: OBJ, OFF,
// PLY, STL through OpenMesh as the service reads uploads). A Status or a mesh, never a crash, a
// sanitizer report or an unbounded allocation. Limits are kept
// small so that a declared count cannot make one input take seconds.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/io/declared_mesh_size.h"
#include "core/io/mesh_io.h"

namespace {

// The format this executable fuzzes, named once, so that the OBJ-only check below is decided at
// compile time (comparing the macro's constant with kObj directly is a self-comparison in the OBJ
// build).
constexpr deform::MeshFormat kFormat = deform::MeshFormat::DEFORM_FUZZ_MESH_FORMAT;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  deform::MeshLimits limits;
  limits.max_vertices = 20'000;
  limits.max_triangles = 40'000;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto declared = deform::ReadDeclaredMeshSize(bytes, kFormat);
  if constexpr (kFormat == deform::MeshFormat::kObj) {
    if (declared.has_value() && declared->vertices > size) {
      __builtin_trap();  // OBJ's counts are lines of the input
    }
  }
  auto mesh = deform::ReadMesh(bytes, kFormat, limits);
  if (mesh.ok() && mesh->num_vertices() > 20'000) __builtin_trap();
  return 0;
}
