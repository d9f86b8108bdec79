// The meshes the benchmarks run on (the built-in phantom and, where ../shared/data is present,
// the 1.6k and 26k legs and the 133k arm) and their models, built once per rotation blend.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/geometry/bone_surface.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"

namespace deform::bench {

struct BenchMesh {
  std::string name;
  std::string mesh_path;  // empty: the phantom
  std::string skeleton_path;
  std::string pose_spec;       // the benchmarks' pose
  std::string flexion_prefix;  // the flexion at DEG degrees is flexion_prefix + DEG
  int phantom_vertices = kDefaultPhantomVertices;  // the phantom's size (mesh_path empty)
};

// The meshes present (a line on stderr for each shared mesh absent).
std::vector<BenchMesh> AvailableMeshes();
// More meshes for the numeric factorization's scaling alone: the 8k arm (where present) and the
// phantom at 20k and 200k vertices.
std::vector<BenchMesh> FactorizationScalingMeshes();

// The paper's model of `mesh` (built once per rotation blend and kept for the later benchmarks);
// null when it cannot be built.
std::shared_ptr<const DeformationModel> ModelFor(const BenchMesh& mesh,
                                                 RotationBlend blend = RotationBlend::kQuaternion);

// A limb with bones: its bone surfaces (the phantom's own; capsules by the sizing rule,
// MakeCapsuleBoneSurfaces, on the shared meshes) and its model built for them with the default
// constraints (the reached skin unanchored: UnanchorReachedSkin). Built once and kept; model null
// when it cannot be built.
struct BonedModel {
  std::shared_ptr<const DeformationModel> model;
  std::vector<BoneSurface> surfaces;
};
BonedModel BonedModelFor(const BenchMesh& mesh);

// The pose `spec` on `model`'s skeleton (the rest pose when it does not parse).
Pose PoseFromSpecOrRest(const DeformationModel& model, const std::string& spec);

}  // namespace deform::bench
