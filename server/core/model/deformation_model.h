// The joint-aware Laplacian deformation model (../shared/docs/METHOD.md).
//
// Life cycle (precompute once, solve per frame):
//   1. DeformationModel::Build(mesh, skeleton, options): validation, harmonic bone weights, joint
//      regions and joint centre nodes, differential coordinates, anchors, the fill-reducing
//      ordering and symbolic analysis of the normal equations, and a first numeric factorisation
//      for the default stiffness. Expensive (about 5 s for the 133k-vertex arm).
//   2. model->Factorize(stiffness): a new numeric factorisation for other material weights; the
//      symbolic analysis is reused. Returns a new immutable object; solves running on an older
//      factorisation are not disturbed.
//   3. model->Deform(factorization, pose, &scratch): per frame. const, allocation-free, writes into
//      the caller's scratch. Any number of threads may call it at once on one model and one
//      factorisation, each with its own scratch.
//
// Notation (only in this file's comments): n mesh vertices, m joint centre nodes, K bones.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "core/model/bone_weights.h"
#include "core/model/joint_regions.h"
#include "core/model/linear_pose_response.h"
#include "core/model/stiffness.h"
#include "core/solver/sparse_cholesky.h"

namespace deform {

// How a blend-region vertex's rotation T_i mixes the rotations of its bones.
enum class RotationBlend {
  // Normalised weighted quaternion sum (QLERP; METHOD.md's slerp for two bones, generalised).
  kQuaternion,
  // T_i = sum_k h_ik R_k, not re-normalised. METHOD.md's fast path: the solution is linear in the
  // bone transforms, so a frame can come from a precomputed response without a solve
  // (LinearPoseResponse). Cheaper per frame; differs from kQuaternion in the blend regions.
  kLinear,
};

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
  // centre), chosen by measurement: on the shared 1.6k leg at 90 degrees of flexion the volume
  // change is -2.1% with 1 and -4.2% with METHOD.md's literal "one more neighbour" edge (set
  // joint_node_one_neighbor), against -2.8% for LBS. Finite and in (0, kMaxJointNodeBalance].
  double joint_node_balance = 1.0;
  static constexpr double kMaxJointNodeBalance = 100;
  // Weigh the joint node as exactly one more neighbour (METHOD.md's 1/(d_i + 1)). Default: false.
  bool joint_node_one_neighbor = false;
  // Weight of the rows that move anchor vertices rigidly with their bone. Default: 10.
  double anchor_weight = 10;
  // Anchors are vertices in a bone's rigid zone (harmonic weight 1) at least this many region
  // radii away from every joint centre. Default: 2.
  double anchor_distance_factor = 2.0;
  // Fill-reducing ordering for the Cholesky factor. Default: kAuto (AMD or METIS, whichever
  // fills less).
  Ordering ordering = Ordering::kAuto;
  // Default: kQuaternion.
  RotationBlend rotation_blend = RotationBlend::kQuaternion;
  // With kLinear: a vertex blending two bones interpolates linearly between this many + 1 samples
  // of the pair's quaternion blend (rotation_blend.h); 1 is METHOD.md's plain linear blend, more
  // segments approach the quaternion blend at 3 more response vectors per pair and segment.
  // Vertices blending three or more bones take the plain linear blend. Default: 4; at most
  // kMaxLinearBlendSegments.
  int linear_blend_segments = 4;
  static constexpr int kMaxLinearBlendSegments = 64;
  MeshLimits limits;

  static ModelOptions Paper() { return {}; }
  // The plain Laplacian baseline: `base` with no joint node and every row weight 1.
  static ModelOptions PlainLaplacian(ModelOptions base);
  static ModelOptions PlainLaplacian() { return PlainLaplacian(Paper()); }
};

// Numeric factorisation of the normal equations for one stiffness. Immutable; shared read-only by
// every stream that deforms with it.
class MaterialFactorization {
 public:
  const Stiffness& stiffness() const { return stiffness_; }
  // Per-vertex row weights w_i (n) that this factorisation was built with.
  const Eigen::VectorXd& row_weights() const { return row_weights_; }
  const CholeskyFactor& factor() const { return factor_; }
  // With RotationBlend::kLinear, the precomputed response that replaces the per-frame solve, when
  // a frame reads less from it than a solve reads from the factor (its doubles against twice the
  // factor's non-zeros: two triangular passes); otherwise, and with kQuaternion, null and frames
  // solve.
  const LinearPoseResponse* linear_response() const { return linear_response_.get(); }
  // Seconds of the numeric factorisation, including the linear response when there is one.
  double factor_seconds() const { return factor_seconds_; }

 private:
  friend class DeformationModel;
  Stiffness stiffness_;
  Eigen::VectorXd row_weights_;
  Eigen::VectorXd row_weights_squared_;
  CholeskyFactor factor_;
  std::unique_ptr<const LinearPoseResponse> linear_response_;
  double factor_seconds_ = 0;
  std::uint64_t model_id_ = 0;  // the model that made it (DeformationModel::Owns)
};

// Per-caller buffers for Deform(). Create with DeformationModel::MakeScratch(); one per stream.
// It belongs to the model that made it: another model's Deform() refuses it.
struct DeformScratch {
  std::vector<RigidTransform> bone_transforms;  // K
  std::vector<Eigen::Matrix3d> bone_rotations;  // K, the same rotations as matrices
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> solution;        // (n + m) by 3
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rotated_deltas;  // n by 3
  std::vector<double> solve_work;  // CholeskyFactor::WorkSize()

  // The deformed vertex positions of the last Deform() (n by 3, a view into `solution`).
  auto positions() const { return solution.topRows(num_vertices); }
  int num_vertices = 0;

 private:
  friend class DeformationModel;
  std::uint64_t model_id_ = 0;  // the model that made it; 0 for a default-constructed scratch
};

// Wall-clock split of one Deform() call, in seconds.
struct DeformTimings {
  double right_hand_side = 0;  // forward kinematics, rotation blend, A^T b
  double solve = 0;            // the two triangular solves, or evaluating the linear response
};

// Optional callbacks of DeformationModel::Build(), each run on the calling thread.
struct BuildHooks {
  // Once the mesh and options are checked, before the precomputation. A non-OK status stops the
  // build and is returned (the service checks its memory budget and reports progress here).
  std::function<Status()> validated;
  // Once the weights, regions and symbolic analysis are done, before the first numeric
  // factorisation (for progress reports).
  std::function<void()> precomputed;
};

class DeformationModel {
 public:
  // Builds the model: the expensive precomputation and the default factorisation.
  //
  // Validates its inputs, whoever made them, so callers need not check first: the mesh with
  // ValidateMesh() against options.limits (INVALID_ARGUMENT naming the first problem,
  // RESOURCE_EXHAUSTED for limits) and the options (INVALID_ARGUMENT naming the option: weights
  // positive and finite, joint_node_balance, linear_blend_segments, region radii). The skeleton is
  // valid by construction (Skeleton::Create). Who validates what, end to end: the mesh readers
  // check what parsing needs and return meshes that pass ValidateMesh (core/io/mesh_io.h); Build
  // checks again for direct callers (phantoms, tests, meshes made in code); the service adds only
  // its own limits (options.limits, the memory budget in hooks.validated) and checks nothing twice.
  // INVALID_ARGUMENT also for a mesh component that cannot be anchored (no vertex in a rigid zone).
  static StatusOr<std::shared_ptr<const DeformationModel>> Build(TriangleMesh mesh,
                                                                 Skeleton skeleton,
                                                                 const ModelOptions& options,
                                                                 const BuildHooks& hooks = {});

  // A new factorisation for `stiffness`, reusing the symbolic analysis. INVALID_ARGUMENT for
  // non-finite or non-positive weights, unknown joints or vertex indices out of range.
  StatusOr<std::shared_ptr<const MaterialFactorization>> Factorize(
      const Stiffness& stiffness) const;
  // The factorisation built by Build() for options.default_material.
  const std::shared_ptr<const MaterialFactorization>& default_factorization() const {
    return default_factorization_;
  }

  DeformScratch MakeScratch() const;

  // Deforms the mesh into `pose`; result in scratch->positions(). Precondition: pose sized to
  // this skeleton (Pose::Rest / PoseFromTerms do so). No allocation.
  // With a linear response (factorization.linear_response()), only the forward kinematics and the
  // response's evaluation run (right_hand_side times the former), and the joint nodes' rows of
  // scratch->solution are left as they were.
  // `factorization` and `scratch` must come from this model (Factorize / default_factorization,
  // MakeScratch): checked on every call at O(1) cost (Owns). Given another model's (or a
  // default-constructed scratch), Deform refuses: it returns false and writes nothing, not even
  // `timings`; debug builds assert, as for any programmer error. Returns true otherwise.
  bool Deform(const MaterialFactorization& factorization, const Pose& pose, DeformScratch* scratch,
              DeformTimings* timings = nullptr) const;

  // The two halves of the solving path of Deform(), for tests and diagnostics (they never use the
  // linear response). AssembleRightHandSide writes A^T b ((n + m) by 3) into scratch->solution;
  // SolveInPlace replaces it by the solution. The same ownership check and refusal as Deform.
  bool AssembleRightHandSide(const MaterialFactorization& factorization, const Pose& pose,
                             DeformScratch* scratch) const;
  bool SolveInPlace(const MaterialFactorization& factorization, DeformScratch* scratch) const;
  // Whether both were made by this model (what Deform checks). O(1).
  bool Owns(const MaterialFactorization& factorization, const DeformScratch& scratch) const {
    return factorization.model_id_ == id_ && scratch.model_id_ == id_;
  }
  // The normal matrix A^T A ((n + m) square) that `factorization` factorises.
  Eigen::SparseMatrix<double> NormalMatrix(const MaterialFactorization& factorization) const;

  const TriangleMesh& mesh() const { return mesh_; }
  const Skeleton& skeleton() const { return skeleton_; }
  const ModelOptions& options() const { return options_; }
  const BoneWeights& bone_weights() const { return bone_weights_; }
  const JointRegions& joint_regions() const { return regions_; }
  const std::vector<int>& anchor_vertices() const { return anchors_; }
  // The bone each anchor vertex follows rigidly (same order as anchor_vertices()).
  const std::vector<int>& anchor_bones() const { return anchor_bone_; }
  int num_joint_nodes() const { return num_nodes_; }
  double bounding_box_diagonal() const { return diagonal_; }
  // Seconds spent in Build() before the first numeric factorisation.
  double precompute_seconds() const { return precompute_seconds_; }

  // The memory a model holds, estimated; the one formula behind every memory budget. Before the
  // build, from the mesh's size alone: per vertex its rest and differential coordinates, Laplacian
  // rows (both orientations), bone weights and region data (about 400 bytes in all), plus 12 bytes
  // per triangle; a lower bound of EstimatedBytes(), which adds the default factorisation's factor
  // and linear response once they are known.
  static std::size_t EstimateBytesBeforeBuild(int num_vertices, int num_triangles);
  std::size_t EstimatedBytes() const;

 private:
  DeformationModel() = default;
  // !Owns(factorization, scratch), asserting in debug builds.
  bool RefusesForeign(const MaterialFactorization& factorization,
                      const DeformScratch& scratch) const;
  // AssembleRightHandSide and SolveInPlace without the ownership check.
  void AssembleOwnedRightHandSide(const MaterialFactorization& factorization, const Pose& pose,
                                  DeformScratch* scratch) const;
  void SolveOwnedInPlace(const MaterialFactorization& factorization, DeformScratch* scratch) const;
  Status Precompute();
  StatusOr<std::shared_ptr<const MaterialFactorization>> FactorizeImpl(
      const Stiffness& stiffness) const;
  Eigen::SparseMatrix<double> BuildNormalMatrix(const Eigen::VectorXd& row_weights_squared) const;
  // The linear blend T_i of vertex i (piecewise along pairs; rotation_blend.h).
  Eigen::Matrix3d LinearBlend(int vertex, const std::vector<RigidTransform>& bones,
                              const std::vector<Eigen::Matrix3d>& bone_rotations) const;
  // METHOD.md's precomputed response for `factorization` (its factor and row weights set), or null
  // when it would be larger than the factor.
  std::unique_ptr<const LinearPoseResponse> BuildLinearResponse(
      const MaterialFactorization& factorization) const;

  std::uint64_t id_ = 0;  // unique within the process, never 0 (Owns)
  TriangleMesh mesh_;
  Skeleton skeleton_;
  ModelOptions options_;
  double diagonal_ = 0;
  BoneWeights bone_weights_;
  JointRegions regions_;
  int num_nodes_ = 0;
  std::vector<int> node_joint_;  // joint index of each joint node (m)
  // L' (n by n + m), uniform weights, compressed by rows; and its transpose for A^T b.
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> laplacian_;
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> laplacian_transpose_;
  Positions rest_deltas_;         // n by 3: L' x_rest
  std::vector<int> anchors_;      // vertex indices
  std::vector<int> anchor_bone_;  // the bone each anchor follows
  Positions anchor_rest_;         // anchors by 3
  std::shared_ptr<const SymbolicCholesky> symbolic_;
  std::shared_ptr<const MaterialFactorization> default_factorization_;
  double precompute_seconds_ = 0;
};

}  // namespace deform
