// The skin a bone reaches across a joint: what a limb with bone surfaces must solve rather than
// anchor (ModelOptions::unanchored_vertices).
//
// A rigid zone is anchored to its bone's motion. When the joint next to it turns far, a bone
// surface across that joint (the tibia, at a deep knee flexion) sweeps into skin of the other
// side's rigid zone (the back of the thigh); the frame's contacts must then push anchored vertices,
// and trade the anchors against the contacts: the rigid zone leaves its bone's motion and the
// contacts hold less well. The skin that any bone across a joint can reach within the joint's range
// of motion is therefore left out of the rigid zones: solved like a joint region's skin (with its
// material weight and its bone's rotation), held off the bone by the contacts when it is reached,
// and following its bone, held by its anchored neighbours, when it is not.
//
// The range of motion, per inner joint: each of its degrees of freedom over its range (the others
// at rest), sampled every `step_degrees`; a joint without any, every turn of at most
// `max_degrees` about any axis. The two sides of the joint are what meet: the bones starting there
// turn, the bone carrying it stays, and only their surfaces and the skin nearest to them
// (straight-line distance to the bones) take part, each skin vertex moving rigidly with its bone
// (a turn of a spine joint does not sweep the arms through the trunk). A vertex is reached when
// such a turn puts it inside a surface of the other side.
// For every turn of at most an angle the test is exact up to a sampling of the surface's solid:
// the turns carry a point over the cap of its sphere about the joint within that angle, so the
// vertex is reached when a sample of the solid lies on that cap (widened by the samples' spacing,
// a 24th of the surface's longest side: it errs towards reaching).
#pragma once

#include <vector>

#include "core/base/cancel_token.h"
#include "core/base/status.h"
#include "core/constraints/skin_constraints.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/model/model_options.h"

namespace deform {

struct BoneReachOptions {
  double max_degrees = 120;  // the natural range of a knee or an elbow in flexion
  double step_degrees = 10;
  int axes = 16;             // around the half circle; each turned both ways
  double tilt_degrees = 15;  // and each tilted this far towards the bones, both ways
};

// The reached skin vertices, ascending. `surfaces` checked against `skeleton` by the caller
// (ValidateBoneSurfaces). `cancel` (optional) is checked for every joint and surface:
// FAILED_PRECONDITION "cancelled during the bone reach" once it is cancelled.
StatusOr<std::vector<int>> SkinReachedAcrossJoints(const TriangleMesh& skin,
                                                   const Skeleton& skeleton,
                                                   const std::vector<BoneSurface>& surfaces,
                                                   const BoneReachOptions& options = {},
                                                   const CancelToken* cancel = nullptr);

// What every caller that builds a model for a limb with bone surfaces does before the build: with
// contacts on and `constraints.bone_reach`, the reached skin becomes `model`'s
// unanchored_vertices (replacing any given); otherwise `model` is left as it is.
Status UnanchorReachedSkin(const TriangleMesh& skin, const Skeleton& skeleton,
                           const std::vector<BoneSurface>& surfaces,
                           const ConstraintOptions& constraints, ModelOptions* model,
                           const CancelToken* cancel = nullptr);

}  // namespace deform
