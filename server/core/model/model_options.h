// The options of the deformation model (deformation_model.h), with their defaults, and the checks
// DeformationModel::Build applies to them.
#pragma once

#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/model/joint_regions.h"
#include "core/model/stiffness.h"
#include "core/solver/ordering.h"

namespace deform {

// How a blend-region vertex's rotation T_i mixes the rotations of its bones.
enum class RotationBlend {
  // Normalized weighted quaternion sum (QLERP; METHOD.md's slerp for two bones, generalized).
  kQuaternion,
  // T_i = sum_k h_ik R_k, not re-normalized. METHOD.md's fast path: the solution is linear in the
  // bone transforms, so a frame can come from a precomputed response without a solve
  // (LinearPoseResponse). Cheaper per frame; differs from kQuaternion in the blend regions.
  kLinear,
};

// How a model binds vertices to bones when no skinning weights are given.
enum class BindingMethod {
  // The nearest bone whose closest point the vertex sees through the body, else the bone of the
  // nearest such vertex along the surface (body_binding.h).
  kThroughBody,
  // The nearest bone in straight-line distance: wrong wherever a part lies close to another
  // part's bone (an ear beside a hand); kept for comparison.
  kStraightLine,
};

// The edge weights w_ij of the Laplacian rows L' (cotangent_weights.h). The harmonic bone weights
// always use uniform weights, whose maximum principle keeps them in [0, 1].
enum class LaplacianWeights {
  // 1 per one-ring edge: METHOD.md's reference.
  kUniform,
  // (cot a_ij + cot b_ij) / 2, the mesh's own: follows its metric; negative at obtuse triangles.
  kCotangent,
  // The cotangent weights of the intrinsic Delaunay triangulation of the same surface (edge
  // flips): all non-negative; a flipped edge joins vertices that were not neighbours, so L' has
  // entries outside the one-ring.
  kIntrinsicCotangent,
};

// "uniform", "cotangent", "intrinsic".
const char* LaplacianWeightsName(LaplacianWeights weights);
// The inverse of LaplacianWeightsName; INVALID_ARGUMENT naming the choices for anything else.
StatusOr<LaplacianWeights> LaplacianWeightsFromName(std::string_view name);

struct ModelOptions {
  // Add a joint centre node per inner joint, joined to its region's vertices. Default: true.
  // false with uniform_material gives the plain Laplacian baseline.
  bool use_joint_nodes = true;
  // Every row weight 1 whatever the stiffness (the plain Laplacian baseline). Default: false.
  bool uniform_material = false;
  // Joint regions: radius factor, explicit radii. See JointRegionOptions.
  JointRegionOptions regions;
  // Default material profile for every inner joint. See stiffness.h.
  JointMaterial default_material;
  // Weight of the rows that pin each joint node to its posed joint centre. Default: 1e3.
  double joint_node_weight = 1e3;
  // How much a region vertex's differential coordinate refers to its joint centre rather than its
  // one-ring: delta_i = v_i - (sum_j v_j + lambda d_i o_c) / (d_i (1 + lambda)), i.e. the joint
  // node weighs lambda times the whole one-ring. Default: 1 (half one-ring mean, half joint
  // centre), chosen by measurement: it keeps more volume than METHOD.md's literal "one more
  // neighbour" edge (set joint_node_one_neighbor) and than LBS (docs/method.md, "Joint node
  // edge"). Finite and in (0, kMaxJointNodeBalance].
  double joint_node_balance = 1.0;
  static constexpr double kMaxJointNodeBalance = 100;
  // Weigh the joint node as exactly one more neighbour (METHOD.md's 1/(d_i + 1)). Default: false.
  bool joint_node_one_neighbor = false;
  // The Laplacian rows' edge weights. With weights w_ij, delta_i = v_i - (sum_j w_ij v_j +
  // lambda s_i o_c) / (s_i (1 + lambda)), s_i = sum_j w_ij (the joint node weighs lambda s_i, or
  // with joint_node_one_neighbor the row's mean weight s_i / d_i). Default: kUniform
  // (docs/method.md, "Cotangent weights", says why).
  LaplacianWeights laplacian = LaplacianWeights::kUniform;
  // Weight of the rows that move anchor vertices with their skinning (rigidly with their bone in
  // a rigid zone). Default: 40, the weight at which rigid zones follow linear blend skinning
  // closely without costing volume or clearance (docs/method.md, "Anchors").
  double anchor_weight = 40;
  // Anchors are vertices in a bone's rigid zone (weight 1) at least this many region radii away
  // from every joint centre. Default: 2.
  double anchor_distance_factor = 2.0;
  // ...and at least this fraction of each connected piece of a rigid zone (its vertices farthest
  // from the joints), so that every zone is held in proportion to its size (anchors.h). In [0, 1].
  // Default: 1, every rigid-zone vertex: a rig's rigid parts then follow their bones as its own
  // skinning does (anchoring only the far ones let the zone next to a region drift: docs/method.md,
  // "Anchors"); the joint regions are what the method solves.
  double anchor_min_fraction = 1.0;
  // Vertices kept out of every rigid zone whatever the binding says: solved (with their material
  // weight and their bone's rotation) rather than anchored. For the skin a bone surface across a
  // joint reaches within the joint's range of motion (SkinReachedAcrossJoints,
  // core/constraints/bone_reach.h), which contacts must be free to move. Each bone keeps at least
  // kMinAnchoredFraction of its rigid zone anchored: the vertices of this list farthest from the
  // joints (by relative distance to the region centres) stay rigid beyond that. Indices must be
  // vertices of the mesh. Default: none.
  std::vector<int> unanchored_vertices;
  static constexpr double kMinAnchoredFraction = 0.25;
  // Without given weights: which bone a vertex follows. Default: kThroughBody.
  BindingMethod binding = BindingMethod::kThroughBody;
  // With given weights: a vertex whose largest weight is at least 1 minus this is in that bone's
  // rigid zone (authored weights are rarely exactly 1: libigl's arm has no such vertex). In
  // [0, 0.5). Default: 0.01.
  double rigid_weight_tolerance = 0.01;
  // Fill-reducing ordering for the Cholesky factor. Default: kAuto (AMD or METIS, whichever
  // fills less).
  Ordering ordering = Ordering::kAuto;
  // Default: kQuaternion.
  RotationBlend rotation_blend = RotationBlend::kQuaternion;
  // With kLinear: a vertex's blend interpolates linearly between knots, samples of its bones'
  // quaternion blend on a grid of this resolution over their weights (linear_blend_plan.h); 1 is
  // METHOD.md's plain linear blend, more segments approach the quaternion blend at 3 more response
  // vectors per knot. Default: 4; at most kMaxLinearBlendSegments.
  int linear_blend_segments = 4;
  static constexpr int kMaxLinearBlendSegments = 64;
  // Store a factorization's values in float32 (half the bytes each solve reads; the solve still
  // computes in double) when its double factor holds at least this many bytes and the probe of
  // MaterialFactorization::float32_probe_error() keeps its frames within a quarter of 1e-6 of the
  // diagonal of the double factor's; otherwise the factor stays double. Negative: never (the
  // default). Worth it where the solve is bound by memory (a factor larger than the last-level
  // cache); for factors the caches hold, widening the floats costs more than the bytes save
  // (docs/performance.md, "Float32 factor").
  std::int64_t float32_factor_min_bytes = -1;
  MeshLimits limits;

  static ModelOptions Paper() { return {}; }
  // The plain Laplacian baseline: `base` with no joint node and every row weight 1.
  static ModelOptions PlainLaplacian(ModelOptions base);
};

// The checks Build() applies to the options (the region radii are checked where the regions are
// computed, ComputeJointRegions): INVALID_ARGUMENT naming the option for a joint_node_weight or
// anchor_weight that is not positive and finite, an anchor_distance_factor below 0 (or NaN), an
// anchor_min_fraction outside [0, 1], and a
// joint_node_balance or linear_blend_segments out of its range.
Status ValidateModelOptions(const ModelOptions& options);

}  // namespace deform
