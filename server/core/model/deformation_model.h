// The joint-aware Laplacian deformation model (../shared/docs/METHOD.md).
//
// Life cycle (precompute once, solve per frame):
//   1. DeformationModel::Build(mesh, skeleton, options): validation, harmonic bone weights, joint
//      regions and joint centre nodes, differential coordinates, anchors, the fill-reducing
//      ordering and symbolic analysis of the normal equations, and a first numeric factorization
//      for the default stiffness. Expensive: it grows with the mesh (docs/performance.md, "Time
//      to first frame"); call it off any thread that must stay responsive.
//   2. model->Factorize(stiffness): a new numeric factorization for other material weights; the
//      symbolic analysis is reused. Returns a new immutable object; solves running on an older
//      factorization are not disturbed.
//   3. model->Deform(factorization, pose, &scratch): per frame. const, allocation-free, writes into
//      the caller's scratch. Any number of threads may call it at once on one model and one
//      factorization, each with its own scratch.
//
// Notation (in the comments of the model's headers): n mesh vertices, m joint centre nodes, K
// bones. The pieces: options (model_options.h), the least-squares system (laplacian_system.h), the
// linear response (linear_pose_response.h), weights, regions and stiffness (their own headers).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/base/cancel_token.h"
#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"
#include "core/model/binding_report.h"
#include "core/model/bone_weights.h"
#include "core/model/general_rows.h"
#include "core/model/joint_regions.h"
#include "core/model/laplacian_system.h"
#include "core/model/linear_blend_plan.h"
#include "core/model/linear_pose_response.h"
#include "core/model/model_options.h"
#include "core/model/rigid_rows.h"
#include "core/model/stiffness.h"
#include "core/solver/sparse_cholesky.h"

namespace deform {

// Numeric factorization of the normal equations for one stiffness. Immutable; shared read-only by
// every stream that deforms with it.
class MaterialFactorization {
 public:
  const CholeskyFactor& factor() const { return factor_; }
  // The squared material weight w_i^2 of each vertex row (n) for the stiffness it was built for.
  const Eigen::VectorXd& row_weights_squared() const { return row_weights_squared_; }
  // With RotationBlend::kLinear, the precomputed response that replaces the per-frame solve, when
  // a frame reads less from it than a solve reads from the factor (its doubles against twice the
  // factor's non-zeros: two triangular passes); otherwise, and with kQuaternion, null and frames
  // solve.
  const LinearPoseResponse* linear_response() const { return linear_response_.get(); }
  // Seconds of the numeric factorization, including the linear response when there is one.
  double factor_seconds() const { return factor_seconds_; }
  // The float32 probe (ModelOptions::float32_factor_min_bytes): the largest vertex difference
  // between the rest pose solved with the double factor and with its float32 rounding, relative
  // to the bounding-box diagonal; negative where no probe ran. The factor is stored in float32
  // (factor().stores_float32()) when the probe ran and stayed within kFloat32ProbeTolerance: a
  // quarter of the 1e-6 of the diagonal that frames may differ by (the float32 transport's own
  // rounding), the margin for poses away from the rest pose (how far the error moves across poses
  // on the shared meshes: docs/performance.md, "Float32 factor").
  double float32_probe_error() const { return float32_probe_error_; }
  static constexpr double kFloat32ProbeTolerance = 2.5e-7;
  // The bytes of its right-hand side's precomputed parts: the rigid rows' sums (rigid_rows.h: 3
  // doubles per row of L'^T) and, for the quaternion blend, its slots' weights (general_rows.h: 1
  // double per slot).
  // Unique within the process (never 0), for caches of what depends on one factorization.
  std::uint64_t serial() const { return serial_; }
  std::size_t right_hand_side_bytes() const {
    return (rigid_row_sums_.size() + slot_weights_.size()) * sizeof(double);
  }

 private:
  friend class DeformationModel;
  Eigen::VectorXd row_weights_squared_;  // w_i^2 (n) for the stiffness it was built for
  std::vector<double> rigid_row_sums_;   // RigidRowSums for those weights ((n + m) by 3)
  std::vector<double> slot_weights_;     // GeneralRowsPlan::SlotWeights (quaternion blend only)
  CholeskyFactor factor_;
  std::unique_ptr<const LinearPoseResponse> linear_response_;
  double factor_seconds_ = 0;
  double float32_probe_error_ = -1;
  std::uint64_t model_id_ = 0;  // the model that made it (DeformationModel::Owns)
  std::uint64_t serial_ = 0;
};

// Per-caller buffers for Deform(). Create with DeformationModel::MakeScratch(); one per stream.
// It belongs to the model that made it: another model's Deform() refuses it.
struct DeformScratch {
  std::vector<RigidTransform> bone_transforms;  // K
  // K, the same rotations as matrices, then (linear blend) the knots' (linear_blend_plan.h)
  std::vector<Eigen::Matrix3d> slot_rotations;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> solution;  // (n + m) by 3
  // The quaternion blend: the frame's signed quaternions and r = w^2 T delta of the slots
  // (general_rows.h: 4 doubles per signed quaternion, 3 planes of the slots).
  std::vector<double> signed_quaternions;
  std::vector<double> rotated_slots;
  // The linear blend: n by 3, r = w^2 T delta of the vertices the general rows of L'^T read
  // (rigid_rows.h); the others' rows are never written. Empty for the quaternion blend.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rotated_deltas;
  std::vector<double> solve_work;  // CholeskyFactor::WorkSize()

  // The deformed vertex positions of the last Deform() (n by 3, a view into `solution`).
  auto positions() const { return solution.topRows(num_vertices); }
  int num_vertices = 0;

 private:
  friend class DeformationModel;
  std::uint64_t model_id_ = 0;  // the model that made it; 0 for a default-constructed scratch
};

// Buffers for DeformationModel::DeformBatch(): the batched solve's rows (the frames' right-hand
// sides side by side, in the factor's order) and the frames' rotated deltas. Create with
// MakeBatchScratch(); one per caller that batches (a worker).
struct DeformBatchScratch {
  int max_frames = 0;
  // CholeskyFactor::WorkSizeMany(3 * max_frames), or with a parallel plan at least
  // WorkSizeFramesParallel(plan, max_frames) as well.
  std::vector<double> solve_work;
  // The quaternion blend's rotated deltas of up to max_frames frames side by side
  // (GeneralRowsPlan::Rotate's `frames`); empty under the linear blend.
  std::vector<double> rotated;

 private:
  friend class DeformationModel;
  std::uint64_t model_id_ = 0;
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
  // factorization (for progress reports).
  std::function<void()> precomputed;
  // Polled between the build's phases (validation, binding, joint regions, harmonic weights, the
  // Laplacian system, symbolic analysis, numeric factorization, linear response): once it is
  // cancelled, Build frees what it made and returns FAILED_PRECONDITION "cancelled during
  // <phase>" at the end of the phase in progress. A phase itself is not interrupted (the longest
  // are the symbolic analysis and the numeric factorization: docs/performance.md, "Time to first
  // frame"). Null:
  // never cancelled. Must outlive the Build call.
  const CancelToken* cancel = nullptr;
};

class DeformationModel {
 public:
  // Builds the model: the expensive precomputation and the default factorization.
  //
  // Validates its inputs, whoever made them, so callers need not check first: the mesh with
  // ValidateMesh() against options.limits (INVALID_ARGUMENT naming the first problem,
  // RESOURCE_EXHAUSTED for limits) and the options (INVALID_ARGUMENT naming the option: weights
  // positive and finite, joint_node_balance, linear_blend_segments, region radii). The skeleton is
  // valid by construction (Skeleton::Create). Who validates what, end to end: the mesh readers
  // check what parsing needs and return meshes that pass ValidateMesh (core/io/mesh_io.h); Build
  // checks again for direct callers (phantoms, tests, meshes made in code); the service adds only
  // its own limits (options.limits, the memory budget in hooks.validated) and checks nothing twice.
  // INVALID_ARGUMENT also for a mesh component that cannot be anchored (no vertex in a rigid zone)
  // and for a skeleton that cannot belong to the mesh (CheckSkeletonAgainstMesh: a joint farther
  // than a diagonal from the surface, or none within the mesh's bounding box).
  //
  // Binding (which bones each vertex follows): with `weights` (a rig's own skinning weights, one
  // row per vertex, bones in skeleton order; checked and normalized here), they are the rotation
  // field; a vertex whose largest weight is at least 1 - options.rigid_weight_tolerance is in that
  // bone's rigid zone, the others form the joint regions (weight_binding.h), and anchors follow
  // the vertex's own weights, i.e. the rig's linear blend skinning. Without, options.binding (by
  // default through the body, body_binding.h), harmonic weights inside the joint regions. What came
  // of it is in binding_report().
  static StatusOr<std::shared_ptr<const DeformationModel>> Build(TriangleMesh mesh,
                                                                 Skeleton skeleton,
                                                                 const ModelOptions& options,
                                                                 const BuildHooks& hooks = {});
  static StatusOr<std::shared_ptr<const DeformationModel>> Build(TriangleMesh mesh,
                                                                 Skeleton skeleton,
                                                                 const ModelOptions& options,
                                                                 const SkinWeights* weights,
                                                                 const BuildHooks& hooks = {});

  // A new factorization for `stiffness`, reusing the symbolic analysis. INVALID_ARGUMENT for
  // non-finite or non-positive weights, unknown joints or vertex indices out of range.
  StatusOr<std::shared_ptr<const MaterialFactorization>> Factorize(
      const Stiffness& stiffness) const;
  // The factorization built by Build() for options.default_material.
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

  // Frames solved together at most: three columns each, CholeskyFactor::SolveMany's limit.
  static constexpr int kMaxBatchFrames = kMaxSolveColumns / 3;
  // A batch scratch for up to `max_frames` frames, clamped to [1, kMaxBatchFrames]; with a
  // `parallel` plan (of PlanParallel, parts >= 2) also for DeformBatchParallel with that plan.
  DeformBatchScratch MakeBatchScratch(int max_frames,
                                      const ParallelSolvePlan* parallel = nullptr) const;
  // Deforms `count` frames at once, frame f's poses[f] into scratches[f] (distinct scratches of
  // this model): the right-hand sides are assembled as Deform() does (the quaternion blend's
  // general rows for all frames in one pass, GeneralRowsPlan::MultiplyGeneral), then all are
  // solved in one pass over the factor, so the factor's bytes are read once for the batch. Each
  // frame equals Deform()'s to round-off (1e-12 of the diagonal, tested). With a linear response
  // there is no solve to share and each frame is evaluated alone. No allocation. Refuses (false,
  // nothing written) a count outside [1, batch->max_frames], another model's factorization, scratch
  // or batch scratch, as Deform() does. `timings`, when given, are the whole batch's: every
  // right-hand side (and packing them side by side), then the one solve (and unpacking it).
  bool DeformBatch(const MaterialFactorization& factorization, const Pose* const* poses,
                   DeformScratch* const* scratches, int count, DeformBatchScratch* batch,
                   DeformTimings* timings = nullptr) const;
  // Deform() on several threads: the rotation blend and A^T b split by vertex and row ranges, and
  // the solve by subtrees (CholeskyFactor::Solve3Parallel), each step's parts run through
  // `runner`. `plan` from factor().PlanParallel of any of this model's factorizations (they share
  // the analysis); `work` holds factor().WorkSizeParallel(plan) doubles. The frame equals
  // Deform()'s to round-off (1e-12 of the diagonal, tested). With a linear response or a plan
  // without parts it is Deform(). Allocation-free; refuses another model's arguments as Deform().
  bool DeformParallel(const MaterialFactorization& factorization, const Pose& pose,
                      DeformScratch* scratch, const ParallelSolvePlan& plan, double* work,
                      ParallelRunner* runner, DeformTimings* timings = nullptr) const;
  // DeformBatch() on several threads: the frames' right-hand sides assembled side by side (the
  // quaternion blend's by slot and row ranges for all frames, the linear blend's each frame on one
  // thread), then the batched solve split by subtrees
  // (CholeskyFactor::SolveFramesParallel), both through `runner`. `plan` as DeformParallel's, and
  // `batch` made by MakeBatchScratch with it (or one with as many parts). Each frame equals
  // Deform()'s to round-off (1e-12 of the diagonal, tested). With a linear response or a plan
  // without parts it is DeformBatch(). Allocation-free; refuses what DeformBatch() refuses and a
  // batch scratch too small for the plan.
  bool DeformBatchParallel(const MaterialFactorization& factorization, const Pose* const* poses,
                           DeformScratch* const* scratches, int count, DeformBatchScratch* batch,
                           const ParallelSolvePlan& plan, ParallelRunner* runner,
                           DeformTimings* timings = nullptr) const;
  // The bytes MakeBatchScratch(max_frames, parallel) allocates.
  std::size_t BatchScratchBytes(int max_frames, const ParallelSolvePlan* parallel = nullptr) const;

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
  // The normal matrix A^T A ((n + m) square) that `factorization` factorizes.
  Eigen::SparseMatrix<double> NormalMatrix(const MaterialFactorization& factorization) const;

  const TriangleMesh& mesh() const { return mesh_; }
  const Skeleton& skeleton() const { return skeleton_; }
  const ModelOptions& options() const { return options_; }
  const BoneWeights& bone_weights() const { return bone_weights_; }
  // The quaternion blend's rows of L'^T r laid out for vector units (empty for the linear blend).
  const GeneralRowsPlan& general_rows() const { return general_rows_; }
  // With the linear rotation blend, its knots and per-vertex terms; null otherwise.
  const LinearBlendPlan* linear_blend_plan() const { return linear_blend_plan_.get(); }
  const JointRegions& joint_regions() const { return regions_; }
  const std::vector<int>& anchor_vertices() const { return system_.anchors; }
  // Per vertex: the bone whose rigid zone it is in (it follows that bone alone), or -1.
  const std::vector<int>& rigid_bones() const { return rigid_bones_; }
  // Per vertex: the bone it is bound to (its rigid bone, the bone binding chose for it, or its
  // largest given weight's bone).
  const std::vector<int>& bound_bones() const { return bound_bones_; }
  const BindingReport& binding_report() const { return binding_report_; }
  bool weights_given() const { return given_weights_.has_value(); }
  // The skinning weights Build was given (normalized), for building a variant with the same
  // binding; empty when the model bound automatically.
  const std::optional<SkinWeights>& given_weights() const { return given_weights_; }
  int num_joint_nodes() const { return system_.num_nodes; }
  // What options.laplacian's edge weights came to (flips, negative weights, rows made uniform).
  const LaplacianWeightReport& laplacian_weight_report() const { return system_.weight_report; }
  double bounding_box_diagonal() const { return diagonal_; }
  // Seconds spent in Build() before the first numeric factorization.
  double precompute_seconds() const { return precompute_seconds_; }
  // The build's phases in order, each with its wall-clock seconds: the stretches between the
  // points where a build can be cancelled (BuildHooks::cancel), so each is the longest a cancel
  // waits. Names as in the "cancelled during ..." errors; the last is "the numeric
  // factorization" (with the linear response, if any).
  struct BuildPhase {
    const char* name;
    double seconds;
  };
  const std::vector<BuildPhase>& build_phases() const { return build_phases_; }

  // The memory a model holds, estimated; the one formula behind every memory budget, calibrated
  // against the growth of a server's resident memory when it loads the model (the shared arm's
  // measurement: docs/performance.md, "Memory").
  // EstimatedBytes(), once built: the default factorization's factor, linear response and rigid
  // rows' sums as they are, the rigid rows' bones, plus kBytesPerVertex per vertex (rest and
  // differential coordinates, Laplacian rows in both orientations, bone weights, region data, the
  // normal matrix's pattern the symbolic analysis keeps) and kBytesPerTriangle per triangle.
  // EstimateBytesBeforeBuild(), from the mesh's size alone (admission: what a load is refused on
  // before anything is allocated): the same, with the factor predicted as
  // kFactorBytesPerVertexLog2 * n * log2(n) (the nested-dissection fill of a surface mesh; above
  // the measured factor on the phantoms and the arm, so it errs towards refusing).
  static constexpr std::size_t kBytesPerVertex = 1400;
  static constexpr std::size_t kBytesPerTriangle = 12;
  static constexpr std::size_t kFactorBytesPerVertexLog2 = 80;
  static std::size_t EstimateBytesBeforeBuild(int num_vertices, int num_triangles);
  std::size_t EstimatedBytes() const;
  // The bytes one more factorization for other stiffness (Factorize) holds: the default
  // factorization's factor, linear response and rigid rows' sums (same sparsity, same sizes), the
  // factor as it is built (in double, also where it is then stored in float32).
  std::size_t FactorizationBytes() const;
  // The bytes MakeScratch() allocates: one stream's solve buffers.
  std::size_t ScratchBytes() const;

 private:
  DeformationModel() = default;
  // !Owns(factorization, scratch), asserting in debug builds.
  bool RefusesForeign(const MaterialFactorization& factorization,
                      const DeformScratch& scratch) const;
  // AssembleRightHandSide and SolveInPlace without the ownership check.
  void AssembleOwnedRightHandSide(const MaterialFactorization& factorization, const Pose& pose,
                                  DeformScratch* scratch) const;
  void SolveOwnedInPlace(const MaterialFactorization& factorization, DeformScratch* scratch) const;
  Status Precompute(const SkinWeights* weights, const CancelToken* cancel);
  // The binding steps of Precompute: set regions_, bone_weights_, rigid_bones_, bound_bones_.
  Status BindAutomatically(const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                           const CancelToken* cancel);
  // Replaces result's factor by its float32 rounding when options_.float32_factor_min_bytes asks
  // for it and the rest-pose probe stays within kFloat32ProbeTolerance (MaterialFactorization).
  void RoundFactorToFloat32IfWithinTolerance(MaterialFactorization* result) const;
  // MakeScratch with `solve_work_doubles` of solve work (before default_factorization_ exists).
  DeformScratch MakeScratchWithWork(std::size_t solve_work_doubles) const;
  // Factorize, stopping between the numeric factorization and the linear response when `cancel`
  // (may be null) is cancelled.
  StatusOr<std::shared_ptr<const MaterialFactorization>> FactorizeCancellable(
      const Stiffness& stiffness, const CancelToken* cancel) const;
  Status BindToWeights(const SkinWeights& weights, const VertexAdjacency& adjacency);
  // The vertex rows' weights w_i for `stiffness` (all 1 with uniform_material).
  StatusOr<Eigen::VectorXd> RowWeights(const Stiffness& stiffness) const;
  // The steps of AssembleRightHandSide after the forward kinematics and PrepareSlotRotations:
  // part `part` of `parts` of r = w^2 T delta (the quaternion blend: into scratch->rotated_slots
  // through general_rows_, after PrepareSlotRotations signed the quaternions; the linear blend:
  // into scratch->rotated_deltas' rows that the general rows of L'^T read, rigid_rows.h), then
  // part `part` of L'^T r into scratch->solution (every part's rotation done). Parts are
  // independent within each step.
  void PrepareSlotRotations(DeformScratch* scratch) const;
  void RotateDeltasPart(const MaterialFactorization& factorization, DeformScratch* scratch,
                        int part, int parts) const;
  void MultiplyRotatedPart(const MaterialFactorization& factorization, DeformScratch* scratch,
                           int part, int parts) const;
  struct ParallelAssembly;  // DeformParallel's parts
  struct BatchAssembly;     // AssembleBatch's parts
  // The right-hand sides of a batch (DeformBatch, DeformBatchParallel), each step's parts run
  // through `runner`: under the linear blend a frame a part, under the quaternion blend `parts`
  // parts of each step below.
  void AssembleBatch(const MaterialFactorization& factorization, const Pose* const* poses,
                     DeformScratch* const* scratches, int count, DeformBatchScratch* batch,
                     ParallelRunner* runner, int parts) const;
  // The quaternion blend's batch of right-hand sides, in steps whose parts are independent: each
  // frame's forward kinematics and signed quaternions (PrepareSlotRotations), then part `part` of
  // `parts` of every frame's rotated deltas into batch->rotated, then of every frame's rows of
  // L'^T r (the general rows of all frames at once), then of every frame's constraint targets
  // (the joint nodes' with part 0).
  void PrepareBatchFrames(const Pose* const* poses, DeformScratch* const* scratches,
                          int count) const;
  void RotateBatchPart(const MaterialFactorization& factorization, DeformScratch* const* scratches,
                       int count, DeformBatchScratch* batch, int part, int parts) const;
  void MultiplyBatchPart(const MaterialFactorization& factorization,
                         DeformScratch* const* scratches, int count,
                         const DeformBatchScratch& batch, int part, int parts) const;
  void AddBatchTargetsPart(const Pose* const* poses, DeformScratch* const* scratches, int count,
                           int part, int parts) const;
  // The doubles of a batch scratch's solve work (MakeBatchScratch).
  std::size_t BatchSolveWorkSize(int max_frames, const ParallelSolvePlan* parallel) const;
  // What DeformBatch and DeformBatchParallel refuse (false): see DeformBatch.
  bool RefusesBatch(const MaterialFactorization& factorization, DeformScratch* const* scratches,
                    int count, const DeformBatchScratch& batch) const;
  // Part `part` of `parts` of the anchors: their rows of scratch->solution += anchor_weight^2 *
  // their posed targets, through scratch->slot_rotations (PrepareSlotRotations first), once
  // every part's MultiplyRotatedPart is done. No allocation.
  void AddAnchorTargetsPart(DeformScratch* scratch, int part, int parts) const;
  // The joint nodes' rows += node_weight^2 * their posed joint centres.
  void AddNodeTargets(const Pose& pose, DeformScratch* scratch) const;
  // AddAnchorTargetsPart for every anchor, then AddNodeTargets.
  void AddConstraintTargets(const Pose& pose, DeformScratch* scratch) const;

  std::uint64_t id_ = 0;  // unique within the process, never 0 (Owns)
  TriangleMesh mesh_;
  Skeleton skeleton_;
  ModelOptions options_;
  double diagonal_ = 0;
  BoneWeights bone_weights_;
  // With the linear rotation blend: its knots and per-vertex terms (shared with the responses).
  std::shared_ptr<const LinearBlendPlan> linear_blend_plan_;
  JointRegions regions_;
  std::vector<int> rigid_bones_;
  std::vector<int> bound_bones_;
  std::optional<SkinWeights> given_weights_;
  BindingReport binding_report_;
  LaplacianSystem system_;        // L', the rest deltas, the anchors and joint nodes
  RigidRows rigid_rows_;          // the rows of L'^T r one bone's rotation determines
  GeneralRowsPlan general_rows_;  // the quaternion blend's rows of L'^T r, for vector units
  std::shared_ptr<const SymbolicCholesky> symbolic_;
  std::shared_ptr<const MaterialFactorization> default_factorization_;
  double precompute_seconds_ = 0;
  std::vector<BuildPhase> build_phases_;
  std::chrono::steady_clock::time_point phase_start_;  // during Build
  // Records the phase that ends now (since phase_start_), then checks `cancel` (CheckCancelled).
  Status EndPhase(const CancelToken* cancel, const char* phase);
};

}  // namespace deform
