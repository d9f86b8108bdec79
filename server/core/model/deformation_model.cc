#include "core/model/deformation_model.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/model/rotation_blend.h"

namespace deform {
namespace {

using Clock = std::chrono::steady_clock;
using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Model ids: unique within the process, never 0 (the id of no model).
std::uint64_t NextModelId() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

// Anchors: rigid-zone vertices far from every joint centre; per component, if none is far enough,
// the rigid-zone vertices farthest from the joints (within 90% of the farthest).
std::vector<int> ChooseAnchors(const VertexAdjacency& adjacency, const std::vector<int>& fixed_bone,
                               const JointRegions& regions, double distance_factor) {
  std::vector<int> component;
  const int count = ConnectedComponents(adjacency, &component);
  const int n = static_cast<int>(fixed_bone.size());
  std::vector<double> farthest(count, -1.0);
  std::vector<char> has_far(count, 0);
  for (int i = 0; i < n; ++i) {
    if (fixed_bone[i] < 0) continue;
    const double s = regions.relative_distance[i];
    farthest[component[i]] = std::max(farthest[component[i]], s);
    if (s >= distance_factor) has_far[component[i]] = 1;
  }
  std::vector<int> anchors;
  for (int i = 0; i < n; ++i) {
    if (fixed_bone[i] < 0) continue;
    const double s = regions.relative_distance[i];
    const int c = component[i];
    if (has_far[c] ? s >= distance_factor : s >= 0.9 * farthest[c]) anchors.push_back(i);
  }
  return anchors;
}

// The options Build() checks (the region radii are checked where the regions are computed).
Status CheckOptions(const ModelOptions& options) {
  if (!(options.joint_node_weight > 0) || !(options.anchor_weight > 0) ||
      !std::isfinite(options.joint_node_weight) || !std::isfinite(options.anchor_weight) ||
      !(options.anchor_distance_factor >= 0)) {
    return Status::InvalidArgument("joint node and anchor weights must be positive and finite");
  }
  if (!std::isfinite(options.joint_node_balance) || !(options.joint_node_balance > 0) ||
      options.joint_node_balance > ModelOptions::kMaxJointNodeBalance) {
    return Status::InvalidArgument("joint_node_balance must be finite and in (0, " +
                                   std::to_string(ModelOptions::kMaxJointNodeBalance) + "], got " +
                                   std::to_string(options.joint_node_balance));
  }
  if (options.linear_blend_segments < 1 ||
      options.linear_blend_segments > ModelOptions::kMaxLinearBlendSegments) {
    return Status::InvalidArgument("linear_blend_segments must be in [1, " +
                                   std::to_string(ModelOptions::kMaxLinearBlendSegments) +
                                   "], got " + std::to_string(options.linear_blend_segments));
  }
  return Status::Ok();
}

}  // namespace

ModelOptions ModelOptions::PlainLaplacian(ModelOptions base) {
  base.use_joint_nodes = false;
  base.uniform_material = true;
  return base;
}

StatusOr<std::shared_ptr<const DeformationModel>> DeformationModel::Build(
    TriangleMesh mesh, Skeleton skeleton, const ModelOptions& options, const BuildHooks& hooks) {
  const auto start = Clock::now();
  DEFORM_RETURN_IF_ERROR(ValidateMesh(mesh, options.limits));
  DEFORM_RETURN_IF_ERROR(CheckOptions(options));
  if (hooks.validated) DEFORM_RETURN_IF_ERROR(hooks.validated());
  std::shared_ptr<DeformationModel> model(new DeformationModel());
  model->id_ = NextModelId();
  model->mesh_ = std::move(mesh);
  model->skeleton_ = std::move(skeleton);
  model->options_ = options;
  DEFORM_RETURN_IF_ERROR(model->Precompute());
  model->precompute_seconds_ = SecondsSince(start);
  if (hooks.precomputed) hooks.precomputed();
  DEFORM_ASSIGN_OR_RETURN(model->default_factorization_, model->FactorizeImpl(Stiffness{}));
  spdlog::debug("model built: {} vertices, {} joint nodes, {} anchors, factor {} non-zeros",
                model->mesh_.num_vertices(), model->num_nodes_, model->anchors_.size(),
                model->default_factorization_->factor().nonzeros());
  return std::shared_ptr<const DeformationModel>(std::move(model));
}

Status DeformationModel::Precompute() {
  const int n = mesh_.num_vertices();
  diagonal_ = BoundingBoxDiagonal(mesh_.vertices);
  const VertexAdjacency adjacency = BuildVertexAdjacency(mesh_.triangles, n);
  const std::vector<NearestBone> nearest = NearestBones(mesh_.vertices, skeleton_);
  DEFORM_ASSIGN_OR_RETURN(
      regions_, ComputeJointRegions(mesh_, skeleton_, adjacency, nearest, options_.regions));

  // Rigid zones: outside every joint region, a vertex belongs wholly to its nearest bone.
  std::vector<int> fixed_bone(n, -1);
  for (int i = 0; i < n; ++i) {
    if (regions_.membership_offsets[i] == regions_.membership_offsets[i + 1]) {
      fixed_bone[i] = nearest[i].bone;
    }
  }
  DEFORM_ASSIGN_OR_RETURN(bone_weights_,
                          HarmonicBoneWeights(adjacency, fixed_bone, skeleton_.num_bones()));

  // Joint centre nodes.
  num_nodes_ = options_.use_joint_nodes ? static_cast<int>(regions_.regions.size()) : 0;
  node_joint_.clear();
  for (int c = 0; c < num_nodes_; ++c) node_joint_.push_back(regions_.regions[c].joint);

  // L' (n by n + m): uniform weights over the one-ring plus the joint nodes of the vertex.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(adjacency.neighbors.size() + n * 2);
  for (int i = 0; i < n; ++i) {
    const int nodes = options_.use_joint_nodes
                          ? regions_.membership_offsets[i + 1] - regions_.membership_offsets[i]
                          : 0;
    // Weight of the edge to each joint node, in units of one one-ring edge.
    const double node_edge =
        options_.joint_node_one_neighbor ? 1.0 : options_.joint_node_balance * adjacency.degree(i);
    const double share = 1.0 / (adjacency.degree(i) + nodes * node_edge);
    triplets.emplace_back(i, i, 1.0);
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      triplets.emplace_back(i, adjacency.neighbors[p], -share);
    }
    if (nodes > 0) {
      for (int p = regions_.membership_offsets[i]; p < regions_.membership_offsets[i + 1]; ++p) {
        triplets.emplace_back(i, n + regions_.membership[p], -share * node_edge);
      }
    }
  }
  laplacian_.resize(n, n + num_nodes_);
  laplacian_.setFromTriplets(triplets.begin(), triplets.end());
  laplacian_.makeCompressed();
  laplacian_transpose_ = laplacian_.transpose();
  laplacian_transpose_.makeCompressed();

  Positions rest_with_nodes(n + num_nodes_, 3);
  rest_with_nodes.topRows(n) = mesh_.vertices;
  for (int c = 0; c < num_nodes_; ++c) {
    rest_with_nodes.row(n + c) = regions_.regions[c].centre.transpose();
  }
  rest_deltas_ = laplacian_ * rest_with_nodes;

  anchors_ = ChooseAnchors(adjacency, fixed_bone, regions_, options_.anchor_distance_factor);
  anchor_bone_.resize(anchors_.size());
  anchor_rest_.resize(static_cast<Eigen::Index>(anchors_.size()), 3);
  for (size_t a = 0; a < anchors_.size(); ++a) {
    anchor_bone_[a] = fixed_bone[anchors_[a]];
    anchor_rest_.row(a) = mesh_.vertices.row(anchors_[a]);
  }

  // Symbolic analysis on the pattern of the normal equations (weights 1).
  ColMajorMatrix pattern = laplacian_transpose_ * laplacian_;
  for (int a : anchors_) pattern.coeffRef(a, a) += 1.0;
  for (int c = 0; c < num_nodes_; ++c) pattern.coeffRef(n + c, n + c) += 1.0;
  pattern.makeCompressed();
  DEFORM_ASSIGN_OR_RETURN(symbolic_, SymbolicCholesky::Analyze(pattern, options_.ordering));
  return Status::Ok();
}

StatusOr<std::shared_ptr<const MaterialFactorization>> DeformationModel::Factorize(
    const Stiffness& stiffness) const {
  return FactorizeImpl(stiffness);
}

StatusOr<std::shared_ptr<const MaterialFactorization>> DeformationModel::FactorizeImpl(
    const Stiffness& stiffness) const {
  const auto start = Clock::now();
  const int n = mesh_.num_vertices();
  auto result = std::make_shared<MaterialFactorization>();
  result->model_id_ = id_;
  result->stiffness_ = stiffness;
  if (options_.uniform_material) {
    if (!stiffness.joint_materials.empty() || !stiffness.region_weights.empty() ||
        !stiffness.vertex_weights.empty()) {
      return Status::FailedPrecondition("this model has uniform material; stiffness is fixed");
    }
    result->row_weights_ = Eigen::VectorXd::Ones(n);
  } else {
    DEFORM_ASSIGN_OR_RETURN(
        result->row_weights_,
        MaterialRowWeights(regions_, skeleton_, n, options_.default_material, stiffness));
  }
  result->row_weights_squared_ = result->row_weights_.array().square();

  const ColMajorMatrix normal = BuildNormalMatrix(result->row_weights_squared_);
  DEFORM_ASSIGN_OR_RETURN(result->factor_, CholeskyFactor::Factorize(symbolic_, normal));
  if (options_.rotation_blend == RotationBlend::kLinear) {
    result->linear_response_ = BuildLinearResponse(*result);
  }
  result->factor_seconds_ = SecondsSince(start);
  return std::shared_ptr<const MaterialFactorization>(std::move(result));
}

// A^T A = L'^T W^2 L' + anchor_weight^2 sum e_a e_a^T + node_weight^2 sum e_c e_c^T.
Eigen::SparseMatrix<double> DeformationModel::BuildNormalMatrix(
    const Eigen::VectorXd& row_weights_squared) const {
  const int n = mesh_.num_vertices();
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> weighted = laplacian_;
  for (int i = 0; i < n; ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor, int>::InnerIterator it(weighted, i); it;
         ++it) {
      it.valueRef() *= row_weights_squared[i];
    }
  }
  ColMajorMatrix normal = laplacian_transpose_ * weighted;
  const double anchor2 = options_.anchor_weight * options_.anchor_weight;
  const double node2 = options_.joint_node_weight * options_.joint_node_weight;
  for (int a : anchors_) normal.coeffRef(a, a) += anchor2;
  for (int c = 0; c < num_nodes_; ++c) normal.coeffRef(n + c, n + c) += node2;
  normal.makeCompressed();
  return normal;
}

Eigen::SparseMatrix<double> DeformationModel::NormalMatrix(
    const MaterialFactorization& factorization) const {
  return BuildNormalMatrix(factorization.row_weights_squared_);
}

std::size_t DeformationModel::EstimateBytesBeforeBuild(int num_vertices, int num_triangles) {
  constexpr std::size_t kBytesPerVertex = 400;
  constexpr std::size_t kBytesPerTriangle = 12;
  return static_cast<std::size_t>(num_vertices) * kBytesPerVertex +
         static_cast<std::size_t>(num_triangles) * kBytesPerTriangle;
}

std::size_t DeformationModel::EstimatedBytes() const {
  const LinearPoseResponse* response = default_factorization_->linear_response();
  return default_factorization_->factor().bytes() + (response ? response->bytes() : 0) +
         EstimateBytesBeforeBuild(mesh_.num_vertices(), mesh_.num_triangles());
}

DeformScratch DeformationModel::MakeScratch() const {
  DeformScratch scratch;
  scratch.model_id_ = id_;
  scratch.num_vertices = mesh_.num_vertices();
  scratch.bone_transforms.resize(skeleton_.num_bones());
  scratch.bone_rotations.resize(skeleton_.num_bones());
  scratch.solution.resize(mesh_.num_vertices() + num_nodes_, 3);
  scratch.rotated_deltas.resize(mesh_.num_vertices(), 3);
  scratch.solve_work.resize(default_factorization_->factor().WorkSize());
  return scratch;
}

bool DeformationModel::RefusesForeign(const MaterialFactorization& factorization,
                                      const DeformScratch& scratch) const {
  const bool owned = Owns(factorization, scratch);
  assert(owned && "a factorisation or scratch of another model");
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
  if (timings != nullptr) {
    timings->right_hand_side = std::chrono::duration<double>(solve_start - start).count();
    timings->solve = SecondsSince(solve_start);
  }
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

namespace {

// out = m r for a row-major sparse m and n by 3 row-major r and out. Two partial sums per row, so
// consecutive entries do not wait on each other's adds.
void MultiplySparseBy3(const Eigen::SparseMatrix<double, Eigen::RowMajor, int>& m,
                       const double* __restrict r, double* __restrict out) {
  const int* columns = m.innerIndexPtr();
  const double* values = m.valuePtr();
  const int* row_begin = m.outerIndexPtr();
  for (int row = 0; row < m.outerSize(); ++row) {
    double a0 = 0, a1 = 0, a2 = 0, b0 = 0, b1 = 0, b2 = 0;
    int p = row_begin[row];
    const int end = row_begin[row + 1];
    for (; p + 2 <= end; p += 2) {
      const double* x = r + 3 * static_cast<std::ptrdiff_t>(columns[p]);
      const double* y = r + 3 * static_cast<std::ptrdiff_t>(columns[p + 1]);
      const double u = values[p], v = values[p + 1];
      a0 += u * x[0];
      a1 += u * x[1];
      a2 += u * x[2];
      b0 += v * y[0];
      b1 += v * y[1];
      b2 += v * y[2];
    }
    if (p < end) {
      const double* x = r + 3 * static_cast<std::ptrdiff_t>(columns[p]);
      a0 += values[p] * x[0];
      a1 += values[p] * x[1];
      a2 += values[p] * x[2];
    }
    double* target = out + 3 * static_cast<std::ptrdiff_t>(row);
    target[0] = a0 + b0;
    target[1] = a1 + b1;
    target[2] = a2 + b2;
  }
}

}  // namespace

void DeformationModel::AssembleOwnedRightHandSide(const MaterialFactorization& factorization,
                                                  const Pose& pose, DeformScratch* scratch) const {
  const int n = mesh_.num_vertices();
  ForwardKinematics(skeleton_, pose, &scratch->bone_transforms);
  const auto& bones = scratch->bone_transforms;

  // Rotated, weighted differential coordinates r_i = w_i^2 T_i delta_i, T_i the rotation blend.
  const auto& bw = bone_weights_;
  const auto& w2 = factorization.row_weights_squared_;
  auto& r = scratch->rotated_deltas;
  for (size_t k = 0; k < bones.size(); ++k) {
    scratch->bone_rotations[k] = bones[k].rotation.toRotationMatrix();
  }
  for (int i = 0; i < n; ++i) {
    const int begin = bw.offsets[i], end = bw.offsets[i + 1];
    const Eigen::Vector3d delta = rest_deltas_.row(i).transpose();
    if (end - begin == 1) {  // most vertices: wholly one bone's
      r.row(i) = w2[i] * (scratch->bone_rotations[bw.bones[begin]] * delta).transpose();
      continue;
    }
    if (options_.rotation_blend == RotationBlend::kLinear) {
      r.row(i) = w2[i] * (LinearBlend(i, bones, scratch->bone_rotations) * delta).transpose();
      continue;
    }
    const Eigen::Quaterniond& first = bones[bw.bones[begin]].rotation;
    Eigen::Quaterniond q;
    q.coeffs() = bw.weights[begin] * first.coeffs();
    for (int p = begin + 1; p < end; ++p) {
      const Eigen::Quaterniond& qk = bones[bw.bones[p]].rotation;
      const double sign = first.dot(qk) < 0 ? -1.0 : 1.0;
      q.coeffs() += (sign * bw.weights[p]) * qk.coeffs();
    }
    q.normalize();
    r.row(i) = w2[i] * (q * delta).transpose();
  }

  // A^T b = L'^T r + anchor_weight^2 c + node_weight^2 o.
  auto& rhs = scratch->solution;
  MultiplySparseBy3(laplacian_transpose_, r.data(), rhs.data());
  const double anchor2 = options_.anchor_weight * options_.anchor_weight;
  for (size_t a = 0; a < anchors_.size(); ++a) {
    const Eigen::Vector3d target = bones[anchor_bone_[a]].Apply(anchor_rest_.row(a).transpose());
    rhs.row(anchors_[a]) += anchor2 * target.transpose();
  }
  const double node2 = options_.joint_node_weight * options_.joint_node_weight;
  for (int c = 0; c < num_nodes_; ++c) {
    const Eigen::Vector3d centre = PosedJointPosition(skeleton_, pose, bones, node_joint_[c]);
    rhs.row(n + c) += node2 * centre.transpose();
  }
}

Eigen::Matrix3d DeformationModel::LinearBlend(
    int vertex, const std::vector<RigidTransform>& bones,
    const std::vector<Eigen::Matrix3d>& bone_rotations) const {
  const auto& bw = bone_weights_;
  const int begin = bw.offsets[vertex], end = bw.offsets[vertex + 1];
  const int segments = options_.linear_blend_segments;
  if (end - begin == 2 && segments > 1) {
    // The pair's knots (ordered by bone index, as the response numbers them) around h_b.
    const auto [a, b, h] =
        OrderedPair(bw.bones[begin], bw.weights[begin], bw.bones[begin + 1], bw.weights[begin + 1]);
    const PairSegment segment = SegmentOf(h, segments);
    const auto knot = [&](int j) -> Eigen::Matrix3d {
      if (j == 0) return bone_rotations[a];
      if (j == segments) return bone_rotations[b];
      return PairKnot(bones[a].rotation, bones[b].rotation, static_cast<double>(j) / segments)
          .toRotationMatrix();
    };
    return (1 - segment.upper_weight) * knot(segment.lower) +
           segment.upper_weight * knot(segment.lower + 1);
  }
  Eigen::Matrix3d blend = bw.weights[begin] * bone_rotations[bw.bones[begin]];
  for (int p = begin + 1; p < end; ++p) blend += bw.weights[p] * bone_rotations[bw.bones[p]];
  return blend;
}

// A factorisation made by this model always has a factor: Solve3 cannot refuse it.
void DeformationModel::SolveOwnedInPlace(const MaterialFactorization& factorization,
                                         DeformScratch* scratch) const {
  const Status solved = factorization.factor().Solve3(
      scratch->solution.data(), scratch->solution.data(), scratch->solve_work.data());
  assert(solved.ok());
  (void)solved;
}

// A slot is a rotation the response is linear in: a bone (with its translation) or a knot of a
// pair blend. Column b of a slot's U solves A u = (the right-hand side of that rotation = I, every
// other transform zero)'s column b, since right-hand side coordinate a is
// sum over slots sum_b R[a, b] (that column) + sum over bones t_k[a] (V_k's); see
// linear_pose_response.h.
std::unique_ptr<const LinearPoseResponse> DeformationModel::BuildLinearResponse(
    const MaterialFactorization& factorization) const {
  const int n = mesh_.num_vertices();
  const int num_bones = skeleton_.num_bones();
  const auto& bw = bone_weights_;
  std::vector<int> node_bone(num_nodes_);
  for (int c = 0; c < num_nodes_; ++c) node_bone[c] = skeleton_.IncomingBone(node_joint_[c]);
  // Bones that appear in the right-hand side at all: through blend weights, anchors, joint nodes.
  std::vector<char> appears(num_bones, 0);
  for (int k : bw.bones) appears[k] = 1;
  for (int k : anchor_bone_) appears[k] = 1;
  for (int k : node_bone) {
    if (k < 0) return nullptr;  // a node moving with the root transform (inner joints never do)
    appears[k] = 1;
  }
  std::vector<int> bones;
  std::vector<int> bone_slot(num_bones, -1);
  for (int k = 0; k < num_bones; ++k) {
    if (!appears[k]) continue;
    bone_slot[k] = static_cast<int>(bones.size());
    bones.push_back(k);
  }
  const int num_bone_slots = static_cast<int>(bones.size());

  // The knots of every bone pair some vertex blends, and each vertex's (slot, coefficient) terms:
  // T_i = sum of coefficient * (the slot's rotation).
  const int segments = options_.linear_blend_segments;
  std::vector<LinearPoseResponse::Knot> knots;
  std::map<std::pair<int, int>, int> first_knot;
  std::vector<std::vector<std::pair<int, double>>> terms(n);
  for (int i = 0; i < n; ++i) {
    const int begin = bw.offsets[i], end = bw.offsets[i + 1];
    if (end - begin == 2 && segments > 1) {
      const auto [a, b, h] = OrderedPair(bw.bones[begin], bw.weights[begin], bw.bones[begin + 1],
                                         bw.weights[begin + 1]);
      const auto [it, inserted] =
          first_knot.emplace(std::make_pair(a, b), static_cast<int>(knots.size()));
      if (inserted) {
        for (int j = 1; j < segments; ++j) {
          knots.push_back({a, b, static_cast<double>(j) / segments});
        }
      }
      const auto slot_of_knot = [&](int j) {
        if (j == 0) return bone_slot[a];
        if (j == segments) return bone_slot[b];
        return num_bone_slots + it->second + j - 1;
      };
      const PairSegment segment = SegmentOf(h, segments);
      terms[i] = {{slot_of_knot(segment.lower), 1 - segment.upper_weight},
                  {slot_of_knot(segment.lower + 1), segment.upper_weight}};
    } else {
      for (int p = begin; p < end; ++p)
        terms[i].emplace_back(bone_slot[bw.bones[p]], bw.weights[p]);
    }
  }

  const std::size_t response_doubles =
      (4 * bones.size() + 3 * knots.size()) * static_cast<std::size_t>(n);
  // A frame reads the response once, a solve reads the factor twice: build it when it reads less.
  const CholeskyFactor& factor = factorization.factor();
  if (response_doubles >= 2 * static_cast<std::size_t>(factor.nonzeros())) return nullptr;

  const auto& w2 = factorization.row_weights_squared_;
  const double anchor2 = options_.anchor_weight * options_.anchor_weight;
  const double node2 = options_.joint_node_weight * options_.joint_node_weight;
  std::vector<double> columns(response_doubles);
  Positions weighted_deltas(n, 3);
  Positions rhs(n + num_nodes_, 3);
  std::vector<double> work(factor.WorkSize());
  // rhs rows of the anchors and joint nodes that follow bone k += their weight^2 * target(their
  // rest position): the rest position itself for U, (1, 0, 0) for V.
  const auto add_constraints = [&](int k, const auto& target) {
    for (std::size_t a = 0; a < anchors_.size(); ++a) {
      if (anchor_bone_[a] == k) rhs.row(anchors_[a]) += anchor2 * target(anchor_rest_.row(a));
    }
    for (int c = 0; c < num_nodes_; ++c) {
      if (node_bone[c] == k) {
        rhs.row(n + c) += node2 * target(skeleton_.joint(node_joint_[c]).rest_position.transpose());
      }
    }
  };
  const std::size_t stride = static_cast<std::size_t>(n);
  const int num_slots = num_bone_slots + static_cast<int>(knots.size());
  for (int slot = 0; slot < num_slots; ++slot) {
    const bool is_bone = slot < num_bone_slots;
    const int k = is_bone ? bones[slot] : -1;
    // Bones' four vectors first, then the knots' three (linear_pose_response.h).
    double* response =
        columns.data() +
        (is_bone ? 4 * slot * stride : (4 * bones.size() + 3 * (slot - num_bone_slots)) * stride);
    // U: this slot's rotation = I, every other transform zero.
    weighted_deltas.setZero();
    for (int i = 0; i < n; ++i) {
      for (const auto& [term_slot, coefficient] : terms[i]) {
        if (term_slot == slot) weighted_deltas.row(i) += w2[i] * coefficient * rest_deltas_.row(i);
      }
    }
    MultiplySparseBy3(laplacian_transpose_, weighted_deltas.data(), rhs.data());
    add_constraints(k, [](const Eigen::RowVector3d& rest) { return rest; });
    if (!factor.Solve3(rhs.data(), rhs.data(), work.data()).ok()) return nullptr;
    for (int b = 0; b < 3; ++b) {
      for (int i = 0; i < n; ++i) response[b * stride + i] = rhs(i, b);
    }
    if (!is_bone) continue;
    // V_k: t_k = 1 (the same scalar response for each coordinate), every rotation zero.
    rhs.setZero();
    add_constraints(k, [](const Eigen::RowVector3d&) { return Eigen::RowVector3d(1, 0, 0); });
    if (!factor.Solve3(rhs.data(), rhs.data(), work.data()).ok()) return nullptr;
    for (int i = 0; i < n; ++i) response[3 * stride + i] = rhs(i, 0);
  }
  return std::make_unique<LinearPoseResponse>(n, std::move(bones), std::move(knots),
                                              std::move(columns));
}

}  // namespace deform
