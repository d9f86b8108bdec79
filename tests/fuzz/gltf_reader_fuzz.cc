// libFuzzer target: ReadGltf (skinned glTF 2.0, .gltf JSON with data URIs or .glb) on arbitrary
// bytes: a Status or a rig, never a crash or a sanitizer report. A rig keeps the contract the
// service relies on: every file vertex names a vertex of the mesh (frames and rest positions are
// read through it), and the unused ones are listed ascending. The file's animations are then read
// for that rig (ReadGltfAnimations) and each is sampled before, inside and after its keys: a
// Status or poses, never a crash.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "core/io/gltf_animation.h"
#include "core/io/rig_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  deform::MeshLimits limits;
  limits.max_vertices = 20'000;
  limits.max_triangles = 40'000;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto rig = deform::ReadGltf(bytes, limits);
  if (!rig.ok()) return 0;
  const int vertices = rig->mesh.num_vertices();
  for (const int m : rig->file_vertex_to_mesh) {
    if (m < 0 || m >= vertices) std::abort();
  }
  const std::vector<int>& unused = rig->unused_file_vertices;
  for (std::size_t k = 0; k < unused.size(); ++k) {
    if (unused[k] < 0 || static_cast<std::size_t>(unused[k]) >= rig->file_vertex_to_mesh.size() ||
        (k > 0 && unused[k] <= unused[k - 1])) {
      std::abort();
    }
  }
  const auto animations = deform::ReadGltfAnimations(bytes, rig->skeleton, limits);
  if (!animations.ok()) return 0;
  for (std::size_t a = 0; a < animations->animations.size(); ++a) {
    const deform::GltfAnimation& animation = animations->animations[a];
    for (const double t :
         {animation.start - 1, 0.5 * (animation.start + animation.end), animation.end + 1}) {
      const auto pose = deform::SamplePose(*animations, static_cast<int>(a), t);
      if (pose.ok() && pose->pose.joint_rotations.size() != rig->skeleton.joints().size()) {
        std::abort();
      }
    }
  }
  return 0;
}
