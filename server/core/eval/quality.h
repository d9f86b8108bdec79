// Quality measures of a deformation (METHOD.md, "What to measure").
#pragma once

#include <vector>

#include "core/constraints/bone_contacts.h"
#include "core/geometry/enclosed_volume.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct ClearanceStats {
  double min = 0;            // smallest ratio
  double p01 = 0;            // 1st percentile
  double sink_fraction = 0;  // fraction of vertices with ratio < 0.5
};

// Skin-to-bone clearance: per vertex, its distance to the nearest posed bone segment over the same
// distance at rest. Vertices closer than 1e-9 of the bounding-box diagonal to a bone at rest are
// skipped (their ratio is undefined).
ClearanceStats SkinClearance(const Positions& rest, const Positions& posed,
                             const Skeleton& skeleton, const std::vector<RigidTransform>& bones);

struct QualityReport {
  double volume_change = 0;  // (V_posed - V_rest) / V_rest, signed
  ClearanceStats clearance;
  // max over the rigid-zone vertices of |x_i - LBS_i| / bounding-box diagonal (LBS with the model's
  // own weights: R_k v_i + t_k for a vertex of bone k's rigid zone); 0 when there are none.
  double rigid_zone_error = 0;
  // max over all vertices of |x_i - v_i| / bounding-box diagonal (meaningful for the rest pose).
  double max_displacement = 0;
  // Skin vertices inside a bone surface and the deepest (model units); zero without bones.
  PenetrationSummary bone_penetration;
  // Triangles turned over against LBS of the same pose or crushed to below 1e-12 of their rest
  // area (CountInvertedTriangles, triangle_counts.h).
  int inverted_triangles = 0;
  // Pairs of triangles sharing no corner that intersect (CountSelfIntersections).
  int self_intersections = 0;
};

// All measures at once; the bone penetration when `bone_surfaces` is given.
// `skinned` is linear blend skinning of the same pose with the model's own weights; the rigid-zone
// error is the largest distance from it of the vertices with rigid_bone[i] >= 0 (those that follow
// one bone alone), relative to the rest mesh's bounding-box diagonal.
QualityReport MeasureQuality(const TriangleMesh& rest_mesh, const Positions& posed,
                             const Skeleton& skeleton, const std::vector<RigidTransform>& bones,
                             const Positions& skinned, const std::vector<int>& rigid_bone,
                             const BoneContacts* bone_surfaces = nullptr);

}  // namespace deform
