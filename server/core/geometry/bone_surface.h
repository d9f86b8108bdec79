// Bone surfaces: closed triangle meshes inside the skin, each carried rigidly by a skeleton bone
// (a femur by the thigh's bone), that the skin must stay outside of. How a frame keeps it there:
// core/constraints/skin_constraints.h.
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct BoneSurface {
  std::string name;  // for reports and errors: a file's name, a glTF node's name
  int bone = -1;     // the skeleton bone that carries it
  // A surface that sits across a joint (a patella) may follow a fraction of that joint's
  // rotation: with blend_bone a child bone of `bone` (its head is `bone`'s tail) and blend in
  // [0, 1], the surface turns by slerp(R_bone, R_blend_bone, blend) about the joint they share.
  // -1: it follows `bone` alone.
  int blend_bone = -1;
  double blend = 0;
  TriangleMesh mesh;  // rest pose, model units, outward-oriented
};

// Limits on what a limb's bone surfaces may hold (each surface also meets the skin's MeshLimits).
struct BoneSurfaceLimits {
  int max_surfaces = 64;
  std::size_t max_total_triangles = 2'000'000;
};

// Checks one limb's bone surfaces against its skeleton: bones in range, a blend bone that is a
// child of the bone and a blend in [0, 1], each mesh valid as a skin is (ValidateMesh) and closed
// (every edge shared by two triangles: inside and outside must mean something). INVALID_ARGUMENT
// naming the surface and the problem; RESOURCE_EXHAUSTED beyond `limits`.
Status ValidateBoneSurfaces(const std::vector<BoneSurface>& surfaces, const Skeleton& skeleton,
                            const MeshLimits& mesh_limits = {},
                            const BoneSurfaceLimits& limits = {});

// The rigid motion of surface `surface` in a frame whose bones moved by `bones` (one per skeleton
// bone, ForwardKinematics).
RigidTransform BoneSurfaceTransform(const BoneSurface& surface, const Skeleton& skeleton,
                                    const std::vector<RigidTransform>& bones);

// Bone surfaces made for a skin that has none (the tests' and the benchmarks' stand-ins for
// segmented bones): for every bone a capsule around its segment whose radius r is
// `radius_fraction` of the smallest distance from any skin vertex to the segment (so the rest
// skin is outside every capsule by at least 1 - radius_fraction of that distance), its caps
// stopping r short of the bone's joints (a joint space: two bones meeting at a joint then stay
// apart up to 120 degrees of flexion, as real ones do); a bone shorter than 4 r gets a sphere of
// radius at most a quarter of its length at its middle. Bones closer to the skin than
// `min_radius_fraction` of the skin's bounding-box diagonal (a bone outside or at the surface of
// the skin) get none. Named "<head joint>-<tail joint>".
std::vector<BoneSurface> MakeCapsuleBoneSurfaces(const TriangleMesh& skin, const Skeleton& skeleton,
                                                 double radius_fraction = 0.5,
                                                 double min_radius_fraction = 0.005);

}  // namespace deform
