// The built-in knee phantom: a deterministic closed leg surface (thigh, knee, shin) with its
// skeleton (hip, knee, ankle), the knee's clinical degrees of freedom, and bones inside it. Every
// tool uses it when no mesh is given, so the project runs with no data at all.
//
// Units are decimetres, Y up, toes toward +Z (as the shared leg): hip at y = 8, knee at y = 3.8,
// ankle at y = 0. Knee flexion rotates the shin about +X (positive moves the foot backward).
#pragma once

#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct KneePhantom {
  TriangleMesh mesh;
  Skeleton skeleton;
  // A femur and a tibia (bones 0 and 1) and a patella that turns by half the knee's flexion.
  std::vector<BoneSurface> bones;
};

// Default resolution of the phantom: about 2,000 vertices, the size of the original knee model.
constexpr int kDefaultPhantomVertices = 2000;
// Largest resolution accepted.
constexpr int kMaxPhantomVertices = 2'000'000;

// A phantom with about `target_vertices` vertices (within a few percent; at least 200).
// INVALID_ARGUMENT outside [200, kMaxPhantomVertices]. The same argument gives the same mesh.
StatusOr<KneePhantom> MakeKneePhantom(int target_vertices = kDefaultPhantomVertices);

}  // namespace deform
