#include "core/model/deformation_model.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "core/base/equal_parts.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/geometry/triangle_bvh.h"
#include "core/model/body_binding.h"
#include "core/model/rigid_cores.h"
#include "core/model/weight_binding.h"
#include "core/solver/parallel_solve.h"

namespace deform {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A deformation's timings (when asked for): the right-hand side from `start` to `solve_start`,
// the solve from then to now.
void RecordTimings(Clock::time_point start, Clock::time_point solve_start, DeformTimings* timings) {
  if (timings == nullptr) return;
  timings->right_hand_side = std::chrono::duration<double>(solve_start - start).count();
  timings->solve = SecondsSince(solve_start);
}

// Model ids: unique within the process, never 0 (the id of no model).
std::uint64_t NextModelId() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

// The least fraction of each bone's vertices kept outside every joint region (rigid_cores.h).
constexpr double kMinRigidFraction = 0.2;

// Rigid zones: outside every joint region, a vertex belongs wholly to the bone it is bound to (the
// bone per vertex, -1 inside a region).
std::vector<int> RigidZones(const JointRegions& regions, const std::vector<NearestBone>& nearest) {
  const int n = static_cast<int>(nearest.size());
  std::vector<int> fixed_bone(n, -1);
  for (int i = 0; i < n; ++i) {
    if (regions.membership_offsets[i] == regions.membership_offsets[i + 1]) {
      fixed_bone[i] = nearest[i].bone;
    }
  }
  return fixed_bone;
}

}  // namespace

StatusOr<std::shared_ptr<const DeformationModel>> DeformationModel::Build(
    TriangleMesh mesh, Skeleton skeleton, const ModelOptions& options, const BuildHooks& hooks) {
  return Build(std::move(mesh), std::move(skeleton), options, nullptr, hooks);
}

StatusOr<std::shared_ptr<const DeformationModel>> DeformationModel::Build(
    TriangleMesh mesh, Skeleton skeleton, const ModelOptions& options, const SkinWeights* weights,
    const BuildHooks& hooks) {
  const auto start = Clock::now();
  DEFORM_RETURN_IF_ERROR(ValidateMesh(mesh, options.limits));
  DEFORM_RETURN_IF_ERROR(ValidateModelOptions(options));
  if (hooks.validated) DEFORM_RETURN_IF_ERROR(hooks.validated());
  std::shared_ptr<DeformationModel> model(new DeformationModel());
  model->phase_start_ = start;
  DEFORM_RETURN_IF_ERROR(model->EndPhase(hooks.cancel, "validation"));
  model->id_ = NextModelId();
  model->mesh_ = std::move(mesh);
  model->skeleton_ = std::move(skeleton);
  model->options_ = options;
  DEFORM_RETURN_IF_ERROR(model->Precompute(weights, hooks.cancel));
  model->precompute_seconds_ = SecondsSince(start);
  if (hooks.precomputed) hooks.precomputed();
  DEFORM_ASSIGN_OR_RETURN(model->default_factorization_,
                          model->FactorizeCancellable(Stiffness{}, hooks.cancel));
  model->build_phases_.push_back(
      {"the numeric factorization", model->default_factorization_->factor_seconds()});
  spdlog::debug("model built: {} vertices, {} joint nodes, {} anchors, factor {} non-zeros",
                model->mesh_.num_vertices(), model->system_.num_nodes,
                model->system_.anchors.size(), model->default_factorization_->factor().nonzeros());
  return std::shared_ptr<const DeformationModel>(std::move(model));
}

Status DeformationModel::Precompute(const SkinWeights* weights, const CancelToken* cancel) {
  diagonal_ = BoundingBoxDiagonal(mesh_.vertices);
  const VertexAdjacency adjacency = BuildVertexAdjacency(mesh_.triangles, mesh_.num_vertices());
  const TriangleBvh bvh(mesh_);
  DEFORM_RETURN_IF_ERROR(CheckSkeletonAgainstMesh(mesh_, skeleton_, bvh));
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the mesh's adjacency"));
  binding_report_.warnings.clear();
  if (weights != nullptr) {
    DEFORM_RETURN_IF_ERROR(BindToWeights(*weights, adjacency));
  } else {
    DEFORM_RETURN_IF_ERROR(BindAutomatically(adjacency, bvh, cancel));
  }
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the harmonic weights"));
  system_ = BuildLaplacianSystem(mesh_, adjacency, regions_, rigid_bones_, bone_weights_, options_);
  rigid_rows_ = RigidRows::Find(system_, bone_weights_);
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the Laplacian system"));
  if (options_.rotation_blend == RotationBlend::kLinear) {
    linear_blend_plan_ = std::make_shared<const LinearBlendPlan>(LinearBlendPlan::Build(
        bone_weights_, skeleton_.num_bones(), options_.linear_blend_segments));
  } else {
    general_rows_ = GeneralRowsPlan::Build(system_, rigid_rows_, bone_weights_);
  }
  BindingReport report = ReportBinding(mesh_, skeleton_, adjacency, bvh, bound_bones_, rigid_bones_,
                                       system_.anchors, IsClosed(mesh_.triangles));
  report.source = binding_report_.source;
  report.seen_through_body = binding_report_.seen_through_body;
  report.reached_along_surface = binding_report_.reached_along_surface;
  report.straight_line = binding_report_.straight_line;
  report.warnings.insert(report.warnings.end(), binding_report_.warnings.begin(),
                         binding_report_.warnings.end());
  binding_report_ = std::move(report);
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the binding report"));
  DEFORM_ASSIGN_OR_RETURN(
      symbolic_, SymbolicCholesky::Analyze(NormalMatrixPattern(system_), options_.ordering));
  return EndPhase(cancel, "the symbolic analysis");
}

Status DeformationModel::BindAutomatically(const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                                           const CancelToken* cancel) {
  std::vector<NearestBone> bound;
  if (options_.binding == BindingMethod::kThroughBody) {
    BodyBinding binding = BindThroughBody(mesh_, skeleton_, adjacency, bvh);
    binding_report_.source = "through the body";
    binding_report_.seen_through_body = binding.seen_through_body;
    binding_report_.reached_along_surface = binding.reached_along_surface;
    binding_report_.straight_line = binding.straight_line;
    bound = std::move(binding.bones);
  } else {
    bound = NearestBones(mesh_.vertices, skeleton_);
    binding_report_.source = "straight line";
    binding_report_.straight_line = mesh_.num_vertices();
  }
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the binding"));
  DEFORM_ASSIGN_OR_RETURN(JointRegions regions, ComputeJointRegions(mesh_, skeleton_, adjacency,
                                                                    bound, options_.regions));
  regions_ = KeepRigidCores(mesh_, adjacency, bound, std::move(regions), kMinRigidFraction);
  rigid_bones_ = RigidZones(regions_, bound);
  DEFORM_RETURN_IF_ERROR(ReleaseFromRigidZones(options_.unanchored_vertices,
                                               regions_.relative_distance,
                                               ModelOptions::kMinAnchoredFraction, &rigid_bones_)
                             .status());
  DEFORM_RETURN_IF_ERROR(EndPhase(cancel, "the joint regions"));
  DEFORM_ASSIGN_OR_RETURN(bone_weights_,
                          HarmonicBoneWeights(adjacency, rigid_bones_, skeleton_.num_bones(),
                                              RegionBonesPerVertex(regions_, skeleton_, bound)));
  bound_bones_.resize(bound.size());
  for (std::size_t i = 0; i < bound.size(); ++i) bound_bones_[i] = bound[i].bone;
  return Status::Ok();
}

Status DeformationModel::BindToWeights(const SkinWeights& weights,
                                       const VertexAdjacency& adjacency) {
  DEFORM_ASSIGN_OR_RETURN(
      const SkinWeights normalized,
      NormalizeSkinWeights(weights, mesh_.num_vertices(), skeleton_.num_bones()));
  WeightBinding binding =
      BindFromWeights(mesh_, skeleton_, normalized, options_.rigid_weight_tolerance);
  if (const int anchored =
          AnchorPiecesWithoutRigidVertex(adjacency, options_.rigid_weight_tolerance, &binding);
      anchored > 0) {
    binding_report_.warnings.push_back(
        std::to_string(anchored) +
        " connected piece(s) of the mesh have no vertex weighted at least 1 - "
        "rigid_weight_tolerance to one bone: each follows its best vertex's bone rigidly");
  }
  DEFORM_RETURN_IF_ERROR(CheckEveryComponentAnchored(adjacency, binding.rigid_bone));
  regions_ = RegionsFromWeightBinding(mesh_, skeleton_, adjacency, binding);
  rigid_bones_ = binding.rigid_bone;
  DEFORM_RETURN_IF_ERROR(ReleaseFromRigidZones(options_.unanchored_vertices,
                                               regions_.relative_distance,
                                               ModelOptions::kMinAnchoredFraction, &rigid_bones_)
                             .status());
  bound_bones_ = binding.main_bone;
  bone_weights_ = BoneWeightsFromSkinWeights(normalized);
  given_weights_ = normalized;
  binding_report_.source = "given weights";
  return Status::Ok();
}

Status DeformationModel::EndPhase(const CancelToken* cancel, const char* phase) {
  const auto now = Clock::now();
  build_phases_.push_back({phase, std::chrono::duration<double>(now - phase_start_).count()});
  phase_start_ = now;
  return CheckCancelled(cancel, phase);
}

StatusOr<std::shared_ptr<const MaterialFactorization>> DeformationModel::Factorize(
    const Stiffness& stiffness) const {
  return FactorizeCancellable(stiffness, nullptr);
}

StatusOr<std::shared_ptr<const MaterialFactorization>> DeformationModel::FactorizeCancellable(
    const Stiffness& stiffness, const CancelToken* cancel) const {
  const auto start = Clock::now();
  auto result = std::make_shared<MaterialFactorization>();
  result->model_id_ = id_;
  result->serial_ = NextModelId();
  DEFORM_ASSIGN_OR_RETURN(const Eigen::VectorXd row_weights, RowWeights(stiffness));
  result->row_weights_squared_ = row_weights.array().square();
  result->rigid_row_sums_ = RigidRowSums(system_, rigid_rows_, result->row_weights_squared_);
  if (!linear_blend_plan_) {
    result->slot_weights_ = general_rows_.SlotWeights(result->row_weights_squared_);
  }
  DEFORM_ASSIGN_OR_RETURN(
      result->factor_,
      CholeskyFactor::Factorize(
          symbolic_, deform::NormalMatrix(system_, result->row_weights_squared_), cancel));
  DEFORM_RETURN_IF_ERROR(CheckCancelled(cancel, "the numeric factorization"));
  if (options_.rotation_blend == RotationBlend::kLinear) {
    result->linear_response_ = BuildLinearPoseResponse(
        system_, skeleton_, linear_blend_plan_, result->row_weights_squared_, result->factor_);
  }
  RoundFactorToFloat32IfWithinTolerance(result.get());
  result->factor_seconds_ = SecondsSince(start);
  return std::shared_ptr<const MaterialFactorization>(std::move(result));
}

StatusOr<Eigen::VectorXd> DeformationModel::RowWeights(const Stiffness& stiffness) const {
  const int n = mesh_.num_vertices();
  if (!options_.uniform_material) {
    return MaterialRowWeights(regions_, skeleton_, n, options_.default_material, stiffness);
  }
  if (!stiffness.joint_materials.empty() || !stiffness.region_weights.empty() ||
      !stiffness.vertex_weights.empty()) {
    return Status::FailedPrecondition("this model has uniform material; stiffness is fixed");
  }
  return Eigen::VectorXd(Eigen::VectorXd::Ones(n));
}

Eigen::SparseMatrix<double> DeformationModel::NormalMatrix(
    const MaterialFactorization& factorization) const {
  return deform::NormalMatrix(system_, factorization.row_weights_squared_);
}

namespace {

// Without the factor: per vertex and per triangle (EstimatedBytes).
std::size_t GeometryBytes(int num_vertices, int num_triangles) {
  return static_cast<std::size_t>(std::max(num_vertices, 0)) * DeformationModel::kBytesPerVertex +
         static_cast<std::size_t>(std::max(num_triangles, 0)) * DeformationModel::kBytesPerTriangle;
}

}  // namespace

std::size_t DeformationModel::EstimateBytesBeforeBuild(int num_vertices, int num_triangles) {
  const double n = std::max(num_vertices, 2);
  const auto factor =
      static_cast<std::size_t>(static_cast<double>(kFactorBytesPerVertexLog2) * n * std::log2(n));
  return GeometryBytes(num_vertices, num_triangles) + factor;
}

std::size_t DeformationModel::EstimatedBytes() const {
  const MaterialFactorization& f = *default_factorization_;
  const LinearPoseResponse* response = f.linear_response();
  return f.factor().bytes() + (response ? response->bytes() : 0) + f.right_hand_side_bytes() +
         rigid_rows_.bytes() + general_rows_.bytes() +
         GeometryBytes(mesh_.num_vertices(), mesh_.num_triangles());
}

std::size_t DeformationModel::FactorizationBytes() const {
  const LinearPoseResponse* response = default_factorization_->linear_response();
  return default_factorization_->factor().bytes_as_built() + (response ? response->bytes() : 0) +
         default_factorization_->right_hand_side_bytes();
}

std::size_t DeformationModel::ScratchBytes() const {
  const std::size_t vertices = static_cast<std::size_t>(mesh_.num_vertices());
  const std::size_t bones = static_cast<std::size_t>(skeleton_.num_bones());
  const std::size_t slots =
      linear_blend_plan_ ? static_cast<std::size_t>(linear_blend_plan_->num_slots()) : bones;
  const std::size_t unknowns = vertices + static_cast<std::size_t>(system_.num_nodes);
  const std::size_t rotated = linear_blend_plan_
                                  ? 3 * vertices
                                  : 4 * static_cast<std::size_t>(general_rows_.quaternion_count()) +
                                        general_rows_.rotated_size();
  return bones * sizeof(RigidTransform) + slots * sizeof(Eigen::Matrix3d) +
         (3 * unknowns + rotated) * sizeof(double) +
         default_factorization_->factor().WorkSize() * sizeof(double);
}

void DeformationModel::RoundFactorToFloat32IfWithinTolerance(MaterialFactorization* result) const {
  const CholeskyFactor& exact = result->factor_;
  const std::int64_t min_bytes = options_.float32_factor_min_bytes;
  if (min_bytes < 0 || static_cast<std::int64_t>(exact.bytes()) < min_bytes) return;
  CholeskyFactor rounded = exact.RoundedToFloat32();
  DeformScratch scratch = MakeScratchWithWork(exact.WorkSize());
  if (!AssembleRightHandSide(*result, Pose::Rest(skeleton_), &scratch)) return;
  // The rest pose's right-hand side, solved with each factor (the rounded one in place).
  auto exact_solution = scratch.solution;
  double* const rounded_solution = scratch.solution.data();
  if (!exact.Solve3(exact_solution.data(), exact_solution.data(), scratch.solve_work.data()).ok() ||
      !rounded.Solve3(rounded_solution, rounded_solution, scratch.solve_work.data()).ok()) {
    return;
  }
  const int n = mesh_.num_vertices();
  const double largest =
      (exact_solution.topRows(n) - scratch.positions()).rowwise().norm().maxCoeff();
  result->float32_probe_error_ = diagonal_ > 0 ? largest / diagonal_ : largest;
  if (result->float32_probe_error_ <= MaterialFactorization::kFloat32ProbeTolerance) {
    result->factor_ = std::move(rounded);
    spdlog::debug("factor stored in float32: {} MB, rest pose within {:.2e} of the diagonal",
                  result->factor_.bytes() / 1e6, result->float32_probe_error_);
  } else {
    spdlog::info(
        "factor kept in double: its float32 rounding moves the rest pose by {:.2e} of the "
        "diagonal (tolerance {:.1e})",
        result->float32_probe_error_, MaterialFactorization::kFloat32ProbeTolerance);
  }
}

DeformScratch DeformationModel::MakeScratch() const {
  return MakeScratchWithWork(default_factorization_->factor().WorkSize());
}

DeformScratch DeformationModel::MakeScratchWithWork(std::size_t solve_work_doubles) const {
  DeformScratch scratch;
  scratch.model_id_ = id_;
  scratch.num_vertices = mesh_.num_vertices();
  scratch.bone_transforms.resize(skeleton_.num_bones());
  scratch.slot_rotations.resize(linear_blend_plan_ ? linear_blend_plan_->num_slots()
                                                   : skeleton_.num_bones());
  scratch.solution.resize(mesh_.num_vertices() + system_.num_nodes, 3);
  if (linear_blend_plan_) {
    scratch.rotated_deltas.resize(mesh_.num_vertices(), 3);
  } else {
    scratch.signed_quaternions.resize(4 *
                                      static_cast<std::size_t>(general_rows_.quaternion_count()));
    scratch.rotated_slots.resize(general_rows_.rotated_size());
  }
  scratch.solve_work.resize(solve_work_doubles);
  return scratch;
}

bool DeformationModel::RefusesForeign(const MaterialFactorization& factorization,
                                      const DeformScratch& scratch) const {
  const bool owned = Owns(factorization, scratch);
  assert(owned && "a factorization or scratch of another model");
  return !owned;
}

bool DeformationModel::Deform(const MaterialFactorization& factorization, const Pose& pose,
                              DeformScratch* scratch, DeformTimings* timings) const {
  if (RefusesForeign(factorization, *scratch)) return false;
  const auto start = Clock::now();
  Clock::time_point solve_start;
  if (const LinearPoseResponse* response = factorization.linear_response()) {
    ForwardKinematics(skeleton_, pose, &scratch->bone_transforms);
    solve_start = Clock::now();
    response->Evaluate(scratch->bone_transforms, scratch->solution.data());
  } else {
    AssembleOwnedRightHandSide(factorization, pose, scratch);
    solve_start = Clock::now();
    SolveOwnedInPlace(factorization, scratch);
  }
  RecordTimings(start, solve_start, timings);
  return true;
}

std::size_t DeformationModel::BatchSolveWorkSize(int max_frames,
                                                 const ParallelSolvePlan* parallel) const {
  const CholeskyFactor& factor = default_factorization_->factor();
  const int frames = std::clamp(max_frames, 1, kMaxBatchFrames);
  std::size_t doubles = factor.WorkSizeMany(3 * frames);
  if (parallel != nullptr && parallel->parts >= 2) {
    doubles = std::max(doubles, factor.WorkSizeFramesParallel(*parallel, frames));
  }
  return doubles;
}

DeformBatchScratch DeformationModel::MakeBatchScratch(int max_frames,
                                                      const ParallelSolvePlan* parallel) const {
  DeformBatchScratch batch;
  batch.model_id_ = id_;
  batch.max_frames = std::clamp(max_frames, 1, kMaxBatchFrames);
  batch.solve_work.resize(BatchSolveWorkSize(batch.max_frames, parallel));
  if (!linear_blend_plan_) batch.rotated.resize(batch.max_frames * general_rows_.rotated_size());
  return batch;
}

std::size_t DeformationModel::BatchScratchBytes(int max_frames,
                                                const ParallelSolvePlan* parallel) const {
  const std::size_t rotated = linear_blend_plan_ ? 0
                                                 : std::clamp(max_frames, 1, kMaxBatchFrames) *
                                                       general_rows_.rotated_size();
  return sizeof(double) * (BatchSolveWorkSize(max_frames, parallel) + rotated);
}

bool DeformationModel::RefusesBatch(const MaterialFactorization& factorization,
                                    DeformScratch* const* scratches, int count,
                                    const DeformBatchScratch& batch) const {
  const bool valid = count >= 1 && count <= batch.max_frames && batch.model_id_ == id_;
  assert(valid && "a batch of another model or of a size its scratch does not hold");
  if (!valid) return true;
  for (int f = 0; f < count; ++f) {
    if (RefusesForeign(factorization, *scratches[f])) return true;
  }
  return false;
}

bool DeformationModel::DeformBatch(const MaterialFactorization& factorization,
                                   const Pose* const* poses, DeformScratch* const* scratches,
                                   int count, DeformBatchScratch* batch,
                                   DeformTimings* timings) const {
  if (RefusesBatch(factorization, scratches, count, *batch)) return false;
  if (factorization.linear_response() != nullptr || count == 1) {
    DeformTimings sum;
    for (int f = 0; f < count; ++f) {
      DeformTimings one;
      Deform(factorization, *poses[f], scratches[f], &one);
      sum.right_hand_side += one.right_hand_side;
      sum.solve += one.solve;
    }
    if (timings != nullptr) *timings = sum;
    return true;
  }
  const auto start = Clock::now();
  SerialRunner serial;
  AssembleBatch(factorization, poses, scratches, count, batch, &serial, 1);
  // Each frame's right-hand side is solved where it is: the batched solve gathers the frames'
  // rows into its own and scatters the solutions back.
  double* solutions[kMaxBatchFrames];
  for (int f = 0; f < count; ++f) solutions[f] = scratches[f]->solution.data();
  const auto solve_start = Clock::now();
  const Status solved =
      factorization.factor().SolveFrames(solutions, solutions, count, batch->solve_work.data());
  assert(solved.ok());
  (void)solved;
  RecordTimings(start, solve_start, timings);
  return true;
}

bool DeformationModel::AssembleRightHandSide(const MaterialFactorization& factorization,
                                             const Pose& pose, DeformScratch* scratch) const {
  if (RefusesForeign(factorization, *scratch)) return false;
  AssembleOwnedRightHandSide(factorization, pose, scratch);
  return true;
}

bool DeformationModel::SolveInPlace(const MaterialFactorization& factorization,
                                    DeformScratch* scratch) const {
  if (RefusesForeign(factorization, *scratch)) return false;
  SolveOwnedInPlace(factorization, scratch);
  return true;
}

void DeformationModel::AssembleOwnedRightHandSide(const MaterialFactorization& factorization,
                                                  const Pose& pose, DeformScratch* scratch) const {
  ForwardKinematics(skeleton_, pose, &scratch->bone_transforms);
  PrepareSlotRotations(scratch);
  // A^T b = L'^T r + anchor_weight^2 c + node_weight^2 o, r = w^2 T delta.
  RotateDeltasPart(factorization, scratch, 0, 1);
  MultiplyRotatedPart(factorization, scratch, 0, 1);
  AddConstraintTargets(pose, scratch);
}

void DeformationModel::PrepareSlotRotations(DeformScratch* scratch) const {
  const auto& bones = scratch->bone_transforms;
  auto& rotations = scratch->slot_rotations;
  if (linear_blend_plan_) {
    linear_blend_plan_->SlotRotations(bones, rotations.data());
    return;
  }
  for (size_t k = 0; k < bones.size(); ++k) rotations[k] = bones[k].rotation.toRotationMatrix();
  general_rows_.SignQuaternions(bones, scratch->signed_quaternions.data());
}

void DeformationModel::RotateDeltasPart(const MaterialFactorization& factorization,
                                        DeformScratch* scratch, int part, int parts) const {
  if (!linear_blend_plan_) {
    general_rows_.Rotate(scratch->signed_quaternions.data(), factorization.slot_weights_.data(),
                         scratch->rotated_slots.data(), part, parts);
    return;
  }
  // The linear blend: r_i = w_i^2 T_i delta_i, T_i a linear combination of slot rotations.
  const auto [first, end] = EqualPart(mesh_.num_vertices(), part, parts);
  const auto& bw = bone_weights_;
  const auto& w2 = factorization.row_weights_squared_;
  auto& r = scratch->rotated_deltas;
  const auto& rotations = scratch->slot_rotations;
  const unsigned char* read = rigid_rows_.delta_read.data();
  for (int i = first; i < end; ++i) {
    if (!read[i]) continue;  // only rigid rows, through their sums, use this vertex
    const Eigen::Vector3d delta = system_.rest_deltas.row(i).transpose();
    if (bw.offsets[i + 1] - bw.offsets[i] == 1) {  // wholly one bone's
      r.row(i) = w2[i] * (rotations[bw.bones[bw.offsets[i]]] * delta).transpose();
    } else {
      r.row(i) = w2[i] * (linear_blend_plan_->Blend(i, rotations.data()) * delta).transpose();
    }
  }
}

void DeformationModel::MultiplyRotatedPart(const MaterialFactorization& factorization,
                                           DeformScratch* scratch, int part, int parts) const {
  const double* sums = factorization.rigid_row_sums_.data();
  if (!linear_blend_plan_) {
    general_rows_.Multiply(scratch->slot_rotations.data(), sums, scratch->rotated_slots.data(),
                           scratch->solution.data(), part, parts);
    return;
  }
  const auto [first, end] =
      EqualPart(static_cast<int>(system_.laplacian_transpose.outerSize()), part, parts);
  MultiplyRotatedRows(system_, rigid_rows_, sums, scratch->slot_rotations.data(),
                      scratch->rotated_deltas.data(), scratch->solution.data(), first, end);
}

struct DeformationModel::ParallelAssembly {
  const DeformationModel* model;
  const MaterialFactorization* factorization;
  DeformScratch* scratch;
  int parts;

  static void Rotate(void* context, int index) {
    const auto& a = *static_cast<const ParallelAssembly*>(context);
    a.model->RotateDeltasPart(*a.factorization, a.scratch, index, a.parts);
  }
  static void Multiply(void* context, int index) {
    const auto& a = *static_cast<const ParallelAssembly*>(context);
    a.model->MultiplyRotatedPart(*a.factorization, a.scratch, index, a.parts);
  }
  // Once every row holds its product (the parts' rows interleave).
  static void Anchors(void* context, int index) {
    const auto& a = *static_cast<const ParallelAssembly*>(context);
    a.model->AddAnchorTargetsPart(a.scratch, index, a.parts);
  }
};

bool DeformationModel::DeformParallel(const MaterialFactorization& factorization, const Pose& pose,
                                      DeformScratch* scratch, const ParallelSolvePlan& plan,
                                      double* work, ParallelRunner* runner,
                                      DeformTimings* timings) const {
  if (factorization.linear_response() != nullptr || plan.parts < 2) {
    return Deform(factorization, pose, scratch, timings);
  }
  if (RefusesForeign(factorization, *scratch)) return false;
  const auto start = Clock::now();
  ForwardKinematics(skeleton_, pose, &scratch->bone_transforms);
  PrepareSlotRotations(scratch);
  ParallelAssembly assembly{this, &factorization, scratch, plan.parts};
  runner->Run(plan.parts, &ParallelAssembly::Rotate, &assembly);
  runner->Run(plan.parts, &ParallelAssembly::Multiply, &assembly);
  runner->Run(plan.parts, &ParallelAssembly::Anchors, &assembly);
  AddNodeTargets(pose, scratch);
  const auto solve_start = Clock::now();
  const Status solved = factorization.factor().Solve3Parallel(
      plan, scratch->solution.data(), scratch->solution.data(), work, runner);
  assert(solved.ok());
  (void)solved;
  RecordTimings(start, solve_start, timings);
  return true;
}

void DeformationModel::PrepareBatchFrames(const Pose* const* poses, DeformScratch* const* scratches,
                                          int count) const {
  for (int f = 0; f < count; ++f) {
    ForwardKinematics(skeleton_, *poses[f], &scratches[f]->bone_transforms);
    PrepareSlotRotations(scratches[f]);
  }
}

void DeformationModel::RotateBatchPart(const MaterialFactorization& factorization,
                                       DeformScratch* const* scratches, int count,
                                       DeformBatchScratch* batch, int part, int parts) const {
  const double* quaternions[kMaxBatchFrames] = {};
  for (int f = 0; f < count; ++f) quaternions[f] = scratches[f]->signed_quaternions.data();
  general_rows_.RotateFrames(quaternions, count, factorization.slot_weights_.data(),
                             batch->rotated.data(), part, parts);
}

void DeformationModel::MultiplyBatchPart(const MaterialFactorization& factorization,
                                         DeformScratch* const* scratches, int count,
                                         const DeformBatchScratch& batch, int part,
                                         int parts) const {
  double* outs[kMaxBatchFrames] = {};
  for (int f = 0; f < count; ++f) outs[f] = scratches[f]->solution.data();
  const double* sums = factorization.rigid_row_sums_.data();
  general_rows_.MultiplyGeneral(batch.rotated.data(), count, outs, part, parts);
  for (int f = 0; f < count; ++f) {
    general_rows_.MultiplyRigid(scratches[f]->slot_rotations.data(), sums, outs[f], part, parts);
  }
}

void DeformationModel::AddBatchTargetsPart(const Pose* const* poses,
                                           DeformScratch* const* scratches, int count, int part,
                                           int parts) const {
  for (int f = 0; f < count; ++f) {
    AddAnchorTargetsPart(scratches[f], part, parts);
    if (part == 0) AddNodeTargets(*poses[f], scratches[f]);
  }
}

struct DeformationModel::BatchAssembly {
  const DeformationModel* model;
  const MaterialFactorization* factorization;
  const Pose* const* poses;
  DeformScratch* const* scratches;
  int count;
  DeformBatchScratch* batch;
  int parts;

  // The linear blend: frame `index`'s right-hand side, whole, on the thread that takes it.
  static void Assemble(void* context, int index) {
    const auto& a = *static_cast<const BatchAssembly*>(context);
    a.model->AssembleOwnedRightHandSide(*a.factorization, *a.poses[index], a.scratches[index]);
  }
  // The quaternion blend's steps (RotateBatchPart and on), each once every part of the one
  // before is done.
  static void Rotate(void* context, int index) {
    const auto& a = *static_cast<const BatchAssembly*>(context);
    a.model->RotateBatchPart(*a.factorization, a.scratches, a.count, a.batch, index, a.parts);
  }
  static void Multiply(void* context, int index) {
    const auto& a = *static_cast<const BatchAssembly*>(context);
    a.model->MultiplyBatchPart(*a.factorization, a.scratches, a.count, *a.batch, index, a.parts);
  }
  static void Targets(void* context, int index) {
    const auto& a = *static_cast<const BatchAssembly*>(context);
    a.model->AddBatchTargetsPart(a.poses, a.scratches, a.count, index, a.parts);
  }
};

void DeformationModel::AssembleBatch(const MaterialFactorization& factorization,
                                     const Pose* const* poses, DeformScratch* const* scratches,
                                     int count, DeformBatchScratch* batch, ParallelRunner* runner,
                                     int parts) const {
  BatchAssembly assembly{this, &factorization, poses, scratches, count, batch, parts};
  if (linear_blend_plan_) {
    runner->Run(count, &BatchAssembly::Assemble, &assembly);
    return;
  }
  PrepareBatchFrames(poses, scratches, count);
  runner->Run(parts, &BatchAssembly::Rotate, &assembly);
  runner->Run(parts, &BatchAssembly::Multiply, &assembly);
  runner->Run(parts, &BatchAssembly::Targets, &assembly);
}

bool DeformationModel::DeformBatchParallel(const MaterialFactorization& factorization,
                                           const Pose* const* poses,
                                           DeformScratch* const* scratches, int count,
                                           DeformBatchScratch* batch, const ParallelSolvePlan& plan,
                                           ParallelRunner* runner, DeformTimings* timings) const {
  if (factorization.linear_response() != nullptr || plan.parts < 2) {
    return DeformBatch(factorization, poses, scratches, count, batch, timings);
  }
  if (RefusesBatch(factorization, scratches, count, *batch)) return false;
  const bool fits =
      batch->solve_work.size() >= factorization.factor().WorkSizeFramesParallel(plan, count);
  assert(fits && "a batch scratch made without this plan");
  if (!fits) return false;
  const auto start = Clock::now();
  AssembleBatch(factorization, poses, scratches, count, batch, runner, plan.parts);
  double* solutions[kMaxBatchFrames];
  for (int f = 0; f < count; ++f) solutions[f] = scratches[f]->solution.data();
  const auto solve_start = Clock::now();
  const Status solved = factorization.factor().SolveFramesParallel(
      plan, solutions, solutions, count, batch->solve_work.data(), runner);
  assert(solved.ok());
  (void)solved;
  RecordTimings(start, solve_start, timings);
  return true;
}

// scratch->solution's anchor and joint-node rows += weight^2 * their posed targets.
void DeformationModel::AddConstraintTargets(const Pose& pose, DeformScratch* scratch) const {
  AddAnchorTargetsPart(scratch, 0, 1);
  AddNodeTargets(pose, scratch);
}

// An anchor's target is sum_e weight_e (R_e rest + t_e) over its bones' entries, R_e as the
// matrix PrepareSlotRotations made of the bone's rotation (slot k < K is bone k's).
void DeformationModel::AddAnchorTargetsPart(DeformScratch* scratch, int part, int parts) const {
  if (!linear_blend_plan_) {
    general_rows_.AddAnchorTargets(scratch->slot_rotations.data(), scratch->bone_transforms,
                                   scratch->solution.data(), part, parts);
    return;
  }
  const auto [first, end] = EqualPart(static_cast<int>(system_.anchors.size()), part, parts);
  const auto& bones = scratch->bone_transforms;
  const auto& rotations = scratch->slot_rotations;
  auto& rhs = scratch->solution;
  const double anchor2 = system_.anchor_weight * system_.anchor_weight;
  for (int a = first; a < end; ++a) {
    const Eigen::Vector3d rest = system_.anchor_rest.row(a).transpose();
    Eigen::Vector3d target = Eigen::Vector3d::Zero();
    for (int e = system_.anchor_offsets[a]; e < system_.anchor_offsets[a + 1]; ++e) {
      const int bone = system_.anchor_bones[e];
      target += system_.anchor_weights[e] * (rotations[bone] * rest + bones[bone].translation);
    }
    rhs.row(system_.anchors[a]) += anchor2 * target.transpose();
  }
}

void DeformationModel::AddNodeTargets(const Pose& pose, DeformScratch* scratch) const {
  const int n = mesh_.num_vertices();
  const auto& bones = scratch->bone_transforms;
  auto& rhs = scratch->solution;
  const double node2 = system_.node_weight * system_.node_weight;
  for (int c = 0; c < system_.num_nodes; ++c) {
    const Eigen::Vector3d centre =
        PosedJointPosition(skeleton_, pose, bones, system_.node_joints[c]);
    rhs.row(n + c) += node2 * centre.transpose();
  }
}

// A factorization made by this model always has a factor: Solve3 cannot refuse it.
void DeformationModel::SolveOwnedInPlace(const MaterialFactorization& factorization,
                                         DeformScratch* scratch) const {
  const Status solved = factorization.factor().Solve3(
      scratch->solution.data(), scratch->solution.data(), scratch->solve_work.data());
  assert(solved.ok());
  (void)solved;
}

}  // namespace deform
