#include "core/constraints/skin_constraints.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry/rotated_fields.h"

namespace deform {
namespace {

using Vec3 = Eigen::Map<const Eigen::Vector3d>;

// Four partial sums, so that the multiply-adds do not wait on each other and the compiler can pair
// them in vector registers (a single running sum is bound by the add's latency).
double Dot(const double* a, const double* b, std::size_t count) {
  double sum[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    sum[0] += a[i] * b[i];
    sum[1] += a[i + 1] * b[i + 1];
    sum[2] += a[i + 2] * b[i + 2];
    sum[3] += a[i + 3] * b[i + 3];
  }
  for (; i < count; ++i) sum[0] += a[i] * b[i];
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

// Overwrites the q-square symmetric positive semi-definite system `a` (row-major, stride
// `stride`) by its Cholesky factor. Pivots are regularised by a tiny multiple of the largest
// diagonal entry, so a degenerate set (two contacts on one vertex's plane) still gives a
// solution. The factor's leading p-square block is the leading block's factor, for any p <= q.
void FactorSymmetric(double* a, int q, int stride) {
  double largest = 0;
  for (int i = 0; i < q; ++i) largest = std::max(largest, a[i * stride + i]);
  const double floor = 1e-12 * std::max(largest, 1e-300);
  for (int j = 0; j < q; ++j) {
    const double* row_j = a + j * stride;
    const double d = std::sqrt(std::max(row_j[j] - Dot(row_j, row_j, j), floor));
    a[j * stride + j] = d;
    for (int i = j + 1; i < q; ++i) {
      double* row_i = a + i * stride;
      row_i[j] = (row_i[j] - Dot(row_i, row_j, j)) / d;
    }
  }
}

// Solves with the leading q-square block of a FactorSymmetric factor, for `x` in place.
void SubstituteSymmetric(const double* a, int q, int stride, double* x) {
  for (int i = 0; i < q; ++i) {
    double v = x[i];
    for (int p = 0; p < i; ++p) v -= a[i * stride + p] * x[p];
    x[i] = v / a[i * stride + i];
  }
  for (int i = q - 1; i >= 0; --i) {
    double v = x[i];
    for (int p = i + 1; p < q; ++p) v -= a[p * stride + i] * x[p];
    x[i] = v / a[i * stride + i];
  }
}

double CubicAt(const double cubic[4], double t) {
  return cubic[0] + t * (cubic[1] + t * (cubic[2] + t * cubic[3]));
}

// The root of cubic(t) = target next to `start` (Newton from there), or `start` where the slope
// vanishes.
double CubicRoot(const double cubic[4], double target, double start) {
  double t = start;
  for (int step = 0; step < 8; ++step) {
    const double value = CubicAt(cubic, t) - target;
    const double slope = cubic[1] + t * (2 * cubic[2] + t * 3 * cubic[3]);
    if (!(std::abs(slope) > 0)) break;
    const double next = t - value / slope;
    if (!std::isfinite(next)) break;
    const bool settled = std::abs(next - t) <= 1e-14 * std::max(1.0, std::abs(t));
    t = next;
    if (settled) break;
  }
  return t;
}

// A model's factorization always has a factor, and the column counts are in range: its solves
// cannot refuse.
void Solved(const Status& status) {
  assert(status.ok());
  (void)status;
}

}  // namespace

StatusOr<std::shared_ptr<const SkinConstraints>> SkinConstraints::Create(
    const DeformationModel& model, std::shared_ptr<const BoneContacts> bones,
    const ConstraintOptions& options) {
  if (!(options.contact_margin >= 0 && options.contact_margin < 1)) {
    return Status::InvalidArgument("contact_margin must be in [0, 1)");
  }
  if ((options.max_contacts < 0 && options.max_contacts != ConstraintOptions::kAutomaticContacts) ||
      options.max_contacts > ConstraintOptions::kMaxContacts) {
    return Status::InvalidArgument(
        "max_contacts must be in [0, " + std::to_string(ConstraintOptions::kMaxContacts) +
        "] or automatic (" + std::to_string(ConstraintOptions::kAutomaticContacts) + ")");
  }
  if (options.max_tool_contacts < 0 ||
      options.max_tool_contacts > ConstraintOptions::kMaxToolContacts) {
    return Status::InvalidArgument("max_tool_contacts must be in [0, " +
                                   std::to_string(ConstraintOptions::kMaxToolContacts) + "]");
  }
  if (!(options.volume_tolerance > 0 && options.volume_tolerance < 1)) {
    return Status::InvalidArgument("volume_tolerance must be in (0, 1)");
  }
  if (options.max_rounds < 1 || options.max_rounds > 16) {
    return Status::InvalidArgument("max_rounds must be in [1, 16]");
  }
  std::shared_ptr<SkinConstraints> constraints(new SkinConstraints());
  constraints->model_ = &model;
  constraints->bones_ = std::move(bones);
  constraints->options_ = options;
  const TriangleMesh& mesh = model.mesh();
  if (options.max_contacts == ConstraintOptions::kAutomaticContacts) {
    constraints->options_.max_contacts =
        ConstraintOptions::AutomaticMaxContacts(mesh.num_vertices());
  }
  constraints->rows_ = mesh.num_vertices() + model.num_joint_nodes();
  constraints->margin_ = options.contact_margin * model.bounding_box_diagonal();
  constraints->closure_ = std::make_unique<VolumeClosure>(mesh.triangles, mesh.num_vertices());
  constraints->rest_volume_ = constraints->closure_->Volume(mesh.vertices.data());
  // The volume is the skin's between its rigid zones: a rigid zone follows its bone, so its
  // vertices carry no share of the correction.
  constraints->volume_free_.resize(mesh.num_vertices());
  bool any_free = false;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    constraints->volume_free_[i] = model.rigid_bones()[i] < 0;
    any_free = any_free || constraints->volume_free_[i];
  }
  const double cube = std::pow(model.bounding_box_diagonal(), 3);
  if (constraints->ContactCapacity() > 0) {
    model.default_factorization()->factor().LongestUnitSolvePath(&constraints->path_columns_,
                                                                 &constraints->path_supernodes_);
  }
  constraints->keeps_volume_ =
      options.keep_volume && any_free && std::abs(constraints->rest_volume_) > 1e-9 * cube;
  if (constraints->keeps_volume_) {
    // The rest volume's gradient, zero off the free vertices.
    std::vector<double> rest_gradient(3 * static_cast<std::size_t>(mesh.num_vertices()));
    constraints->closure_->Gradient(mesh.vertices.data(), rest_gradient.data());
    std::vector<char> used(model.skeleton().num_bones(), 0);
    const BoneWeights& weights = model.bone_weights();
    for (int i = 0; i < mesh.num_vertices(); ++i) {
      if (!constraints->volume_free_[i]) {
        std::fill_n(rest_gradient.begin() + 3 * i, 3, 0.0);
        continue;
      }
      for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) used[weights.bones[e]] = 1;
    }
    for (int k = 0; k < model.skeleton().num_bones(); ++k) {
      if (used[k]) constraints->direction_bones_.push_back(k);
    }
    // h_ik g_rest_i per direction bone k, by coordinate: the posed gradient is their sum, each
    // turned by its bone.
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices());
    std::vector<int> slot(model.skeleton().num_bones(), -1);
    for (std::size_t d = 0; d < constraints->direction_bones_.size(); ++d) {
      slot[constraints->direction_bones_[d]] = static_cast<int>(d);
    }
    std::vector<float>& fields = constraints->gradient_fields_;
    fields.assign(3 * constraints->direction_bones_.size() * n, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
      if (!constraints->volume_free_[i]) continue;
      for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) {
        const std::size_t d = static_cast<std::size_t>(slot[weights.bones[e]]);
        for (std::size_t c = 0; c < 3; ++c) {
          fields[(3 * d + c) * n + i] +=
              static_cast<float>(weights.weights[e] * rest_gradient[3 * i + c]);
        }
      }
    }
    const MaterialFactorization& factorization = *model.default_factorization();
    const std::size_t rows = constraints->rows_;
    constraints->default_directions_.resize(constraints->direction_bones_.size() * 3 * rows);
    std::vector<double> column(3 * rows);
    std::vector<double> work(factorization.factor().WorkSize());
    constraints->SolveBoneDirections(factorization, constraints->default_directions_.data(),
                                     column.data(), work.data());
    constraints->default_products_.resize(constraints->direction_bones_.size() *
                                          constraints->direction_bones_.size());
    constraints->GradientProducts(constraints->default_directions_.data(),
                                  constraints->default_products_.data());
    constraints->default_serial_ = factorization.serial();
  }
  return std::shared_ptr<const SkinConstraints>(std::move(constraints));
}

int ConstraintOptions::AutomaticMaxContacts(int vertices) {
  const int scaled = (std::max(vertices, 0) + kVerticesPerContact - 1) / kVerticesPerContact;
  return std::clamp(scaled, kMinAutomaticContacts, kMaxContacts);
}

int SkinConstraints::ContactCapacity() const {
  return (bones_ != nullptr ? options_.max_contacts : 0) + options_.max_tool_contacts;
}

ConstraintScratch SkinConstraints::MakeScratch() const {
  ConstraintScratch s;
  s.owner = this;
  const std::size_t rows = rows_;
  const std::size_t k = ContactCapacity();
  s.base.resize(3 * rows);
  // Two combinations of the contacts' forward passes (SkinConstraints::Apply) with the volume.
  const bool six_columns = keeps_volume_ && k > 0;
  s.correction.resize((six_columns ? 6 : 3) * rows);
  if (six_columns) {
    s.direction.resize(3 * rows);
    s.shares.resize(k);
  }
  if (keeps_volume_) {
    s.gradient.resize(3 * rows);
    s.h.resize(3 * rows);
    s.bone_directions.resize(direction_bones_.size() * 3 * rows);
    s.direction_products.resize(direction_bones_.size() * direction_bones_.size());
    s.rotations.resize(direction_bones_.size());
  }
  if (k > 0) {
    s.unit_work.assign(model_->default_factorization()->factor().UnitSolvesWorkSize(), 0.0);
    s.unit_columns.resize(k);
    s.paths.resize(k * path_supernodes_);
    s.path_lengths.resize(k);
    s.path_values.resize(k * path_columns_);
    s.found.resize(k);
    s.contacts.resize(k);
    s.inverse_block.resize(k * k);
    s.in_set.assign(model_->mesh().num_vertices(), 0);
  }
  const CholeskyFactor& factor = model_->default_factorization()->factor();
  s.solve_work.resize(std::max(factor.WorkSize(), six_columns ? factor.WorkSizeMany(6) : 0));
  s.system.resize((k + 1) * (k + 1));
  s.multipliers.resize(k + 1);
  return s;
}

std::size_t SkinConstraints::ScratchBytes() const {
  const std::size_t rows = rows_;
  const std::size_t k = ContactCapacity();
  const bool six_columns = keeps_volume_ && k > 0;
  const CholeskyFactor& factor = model_->default_factorization()->factor();
  std::size_t doubles = 6 * rows + (k + 1) * (k + 2) +
                        std::max(factor.WorkSize(), six_columns ? factor.WorkSizeMany(6) : 0);
  std::size_t bytes = 0;
  if (keeps_volume_) {
    doubles += 6 * rows;
    bytes += direction_bones_.size() * (sizeof(Eigen::Matrix3d) + 3 * rows * sizeof(float)) +
             direction_bones_.size() * direction_bones_.size() * sizeof(Eigen::Matrix3d);
  }
  if (six_columns) doubles += 6 * rows + k;
  if (k > 0) {
    doubles += factor.UnitSolvesWorkSize() + k * path_columns_ + k * k;
    bytes += (k * path_supernodes_ + 2 * k) * sizeof(int) + k * sizeof(BonePenetration) +
             k * sizeof(HeldContact) + model_->mesh().num_vertices();
  }
  return bytes + doubles * sizeof(double);
}

double SkinConstraints::PathDot(const CholeskyFactor& factor, const ConstraintScratch& s, int l,
                                int j) const {
  const int* pl = s.paths.data() + static_cast<std::size_t>(l) * path_supernodes_;
  const int* pj = s.paths.data() + static_cast<std::size_t>(j) * path_supernodes_;
  const double* vl = s.path_values.data() + static_cast<std::size_t>(l) * path_columns_;
  const double* vj = s.path_values.data() + static_cast<std::size_t>(j) * path_columns_;
  const int nl = s.path_lengths[l], nj = s.path_lengths[j];
  // Both paths run up to the root in ascending supernodes: merge them.
  double dot = 0;
  for (int a = 0, b = 0; a < nl && b < nj;) {
    if (pl[a] < pj[b]) {
      vl += factor.SupernodeWidth(pl[a++]);
    } else if (pj[b] < pl[a]) {
      vj += factor.SupernodeWidth(pj[b++]);
    } else {
      const int width = factor.SupernodeWidth(pl[a]);
      dot += Dot(vl, vj, width);
      vl += width;
      vj += width;
      ++a;
      ++b;
    }
  }
  return dot;
}

void SkinConstraints::AddContacts(const CholeskyFactor& factor, int count, ObstacleKind kind,
                                  ConstraintScratch* s, ConstraintReport* report) const {
  const std::size_t k = ContactCapacity();
  int& set = report->contacts;
  const int first = set;
  for (int c = 0; c < count; ++c) {
    s->contacts[first + c] = HeldContact{s->found[c], kind};
    s->unit_columns[c] = s->found[c].vertex;
  }
  // The round's paths together: the top supernodes, on every path, are read once a block.
  factor.ForwardUnitSolves(s->unit_columns.data(), count,
                           s->paths.data() + first * static_cast<std::size_t>(path_supernodes_),
                           path_supernodes_, s->path_lengths.data() + first,
                           s->path_values.data() + first * static_cast<std::size_t>(path_columns_),
                           path_columns_, s->unit_work.data());
  report->unit_solves += count;
  set += count;
  for (int j = first; j < set; ++j) {
    for (int l = 0; l <= j; ++l) {
      const double v = PathDot(factor, *s, l, j);
      s->inverse_block[l * k + j] = v;
      s->inverse_block[j * k + l] = v;
    }
  }
}

void SkinConstraints::MoveContact(int from, int to, int set, ConstraintScratch* s) const {
  const std::size_t k = ContactCapacity();
  s->contacts[to] = s->contacts[from];
  std::copy_n(s->paths.begin() + from * static_cast<std::size_t>(path_supernodes_),
              s->path_lengths[from],
              s->paths.begin() + to * static_cast<std::size_t>(path_supernodes_));
  std::copy_n(s->path_values.begin() + from * static_cast<std::size_t>(path_columns_),
              path_columns_, s->path_values.begin() + to * static_cast<std::size_t>(path_columns_));
  s->path_lengths[to] = s->path_lengths[from];
  for (int l = 0; l < set; ++l) s->inverse_block[to * k + l] = s->inverse_block[from * k + l];
  for (int l = 0; l < set; ++l) s->inverse_block[l * k + to] = s->inverse_block[l * k + from];
  s->inverse_block[to * k + to] = s->inverse_block[from * k + from];
}

double SkinConstraints::PoseVolumeDirections(const MaterialFactorization& factorization,
                                             const std::vector<RigidTransform>& bones,
                                             ConstraintScratch* s, ConstraintReport* report) const {
  const std::size_t rows = rows_;
  const int directions = static_cast<int>(direction_bones_.size());
  const float* bone_directions = default_directions_.data();
  const Eigen::Matrix3d* products = default_products_.data();
  if (factorization.serial() != default_serial_) {
    // Another stiffness: its D_k once per stream and factorization, solved through s->h.
    if (s->directions_serial != factorization.serial()) {
      report->solves += SolveBoneDirections(factorization, s->bone_directions.data(), s->h.data(),
                                            s->solve_work.data());
      GradientProducts(s->bone_directions.data(), s->direction_products.data());
      s->directions_serial = factorization.serial();
    }
    bone_directions = s->bone_directions.data();
    products = s->direction_products.data();
  }
  // M^-1 g = sum_k D_k R_k^T streams the fields once.
  for (int d = 0; d < directions; ++d) {
    s->rotations[d] = bones[direction_bones_[d]].rotation.toRotationMatrix();
  }
  SumRotatedFields(bone_directions, rows, rows, directions, s->rotations.data(), s->h.data());
  return GradientDotDirection(products, s->rotations.data());
}

void SkinConstraints::GradientProducts(const float* directions, Eigen::Matrix3d* products) const {
  const std::size_t rows = rows_;
  const std::size_t n = static_cast<std::size_t>(model_->mesh().num_vertices());
  const std::size_t count = direction_bones_.size();
  for (std::size_t k = 0; k < count; ++k) {
    for (std::size_t l = 0; l < count; ++l) {
      Eigen::Matrix3d& c = products[k * count + l];
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          const float* d = directions + (3 * l + a) * rows;
          const float* f = gradient_fields_.data() + (3 * k + b) * n;
          double sum = 0;
          for (std::size_t i = 0; i < n; ++i) sum += static_cast<double>(d[i]) * f[i];
          c(a, b) = sum;
        }
      }
    }
  }
}

double SkinConstraints::GradientDotDirection(const Eigen::Matrix3d* products,
                                             const Eigen::Matrix3d* rotations) const {
  // g_i . h_i = sum_kl (R_k f_ki) . (R_l d_li) = sum_kl tr(R_k^T R_l d_li f_ki^T).
  const std::size_t count = direction_bones_.size();
  double dot = 0;
  for (std::size_t k = 0; k < count; ++k) {
    for (std::size_t l = 0; l < count; ++l) {
      const Eigen::Matrix3d turn = rotations[k].transpose() * rotations[l];
      dot += turn.cwiseProduct(products[k * count + l].transpose()).sum();
    }
  }
  return dot;
}

int SkinConstraints::SolveBoneDirections(const MaterialFactorization& factorization,
                                         float* bone_directions, double* column,
                                         double* work) const {
  const std::size_t rows = rows_;
  const std::size_t n = static_cast<std::size_t>(model_->mesh().num_vertices());
  const int directions = static_cast<int>(direction_bones_.size());
  // Each D_k is solved in `column`, then laid out by coordinate, as SumRotatedFields reads it.
  for (int d = 0; d < directions; ++d) {
    std::fill(column, column + 3 * rows, 0.0);
    for (std::size_t c = 0; c < 3; ++c) {
      const float* field = gradient_fields_.data() + (3 * d + c) * n;
      for (std::size_t i = 0; i < n; ++i) column[3 * i + c] = field[i];
    }
    Solved(factorization.factor().Solve3(column, column, work));
    for (std::size_t c = 0; c < 3; ++c) {
      float* field = bone_directions + (3 * d + c) * rows;
      for (std::size_t r = 0; r < rows; ++r) field[r] = static_cast<float>(column[3 * r + c]);
    }
  }
  return directions;
}

bool SkinConstraints::Apply(const MaterialFactorization& factorization, DeformScratch* frame,
                            ConstraintScratch* s, ConstraintReport* report,
                            const ToolSet* tools) const {
  *report = {};
  if (!model_->Owns(factorization, *frame) || s->owner != this) return false;
  if (tools != nullptr && tools->empty()) tools = nullptr;
  if (tools != nullptr && !takes_tools()) return false;
  const CholeskyFactor& factor = factorization.factor();
  const std::size_t values = 3 * static_cast<std::size_t>(rows_);
  const int k_max = ContactCapacity();
  const int bone_bound = bones_ != nullptr ? options_.max_contacts : 0;
  const int n = model_->mesh().num_vertices();
  double* x = frame->solution.data();
  std::copy(x, x + values, s->base.begin());
  auto volume_change = [&](double volume) {
    return rest_volume_ != 0 ? volume / rest_volume_ - 1 : 0.0;
  };
  int& set = report->contacts;
  // The last frame's bone contacts, when it had this factorization.
  int carried = 0;
  if (s->kept > 0) {
    if (s->kept_serial == factorization.serial()) {
      carried = s->kept;
    } else {
      for (int j = 0; j < s->kept; ++j) --s->in_set[s->contacts[j].at.vertex];
    }
    s->kept = 0;
  }
  set = carried;
  // The volume of x when a round already knows it (the cubic's value at its mu); NaN otherwise.
  double known_volume = std::numeric_limits<double>::quiet_NaN();
  double cubic[4] = {0, 0, 0, 0};
  // The volume along x* + mu M^-1 g (its value at mu = 0 the volume of x*), once a round needs
  // it: a frame without contacts, in its first round.
  bool cubic_known = false;
  auto need_cubic = [&] {
    if (cubic_known) return;
    closure_->VolumeAlong(s->base.data(), s->h.data(), cubic);
    cubic_known = true;
  };
  // g . M^-1 g, and g itself (s->gradient) once a round needs it: a round after a correction.
  double gradient_dot_h = 0;
  bool gradient_posed = false;
  if (keeps_volume_) {
    gradient_dot_h = PoseVolumeDirections(factorization, frame->bone_transforms, s, report);
  }
  for (int round = 0;; ++round) {
    // The contacts each kind holds now (a tool contact may have taken a bone's plane).
    int bone_held = 0;
    for (int j = 0; j < set; ++j) bone_held += s->contacts[j].kind == ObstacleKind::kBone;
    const int tool_held = set - bone_held;
    PenetrationSummary summary;
    int found = 0;
    if (bones_ != nullptr) {
      const int capacity = std::max(0, std::min(bone_bound - bone_held, k_max - set));
      found = bones_->Find(x, frame->bone_transforms, s->found.data(), capacity, &summary,
                           s->in_set.empty() ? nullptr : s->in_set.data());
      if (round == 0 && carried > 0 && found == capacity && summary.vertices > found) {
        // More skin inside than the bound leaves room for: the carried contacts whose vertex is
        // outside its bone give their slots back, and the search runs again.
        for (int j = carried - 1; j >= 0; --j) {
          BonePenetration inside;
          const HeldContact& held = s->contacts[j];
          if (bones_->Into(held.at.surface, held.at.vertex, x, frame->bone_transforms, &inside)) {
            continue;
          }
          --s->in_set[held.at.vertex];
          if (j != set - 1) MoveContact(set - 1, j, set, s);
          --set;
          --carried;
        }
        bone_held = set;
        const int room = std::max(0, std::min(bone_bound - bone_held, k_max - set));
        found = bones_->Find(x, frame->bone_transforms, s->found.data(), room, &summary,
                             s->in_set.data());
      }
    }
    // The held bone contacts. One still inside its bone (its plane was tangent where the
    // surface curves away) is held on the tangent plane at its new nearest point. One outside it:
    // carried from the last frame, its plane at its nearest point now (its multiplier says
    // whether the frame needs it); pushed into another bone (skin caught between two bones), a
    // second contact there, keeping the first, since holding it on one plane at a time sends it
    // back and forth between the two.
    int refreshed = 0;
    const int bone_capacity = std::max(0, std::min(bone_bound - bone_held, k_max - set));
    for (int j = 0; j < set; ++j) {
      HeldContact& held = s->contacts[j];
      if (held.kind != ObstacleKind::kBone) continue;
      BonePenetration now;
      if (bones_->Into(held.at.surface, held.at.vertex, x, frame->bone_transforms, &now)) {
        held.at.normal = now.normal;
        held.at.surface_point = now.surface_point;
        ++refreshed;
        continue;
      }
      if (round == 0 && j < carried) {
        bones_->OutsidePlane(held.at.surface, held.at.vertex, x, frame->bone_transforms, &now);
        held.at.normal = now.normal;
        held.at.surface_point = now.surface_point;
      }
      if (found >= bone_capacity ||
          !bones_->Deepest(held.at.vertex, x, frame->bone_transforms, &now)) {
        continue;
      }
      bool held_there = false;
      for (int l = 0; l < set && !held_there; ++l) {
        held_there = s->contacts[l].at.vertex == now.vertex &&
                     s->contacts[l].kind == ObstacleKind::kBone &&
                     s->contacts[l].at.surface == now.surface;
      }
      for (int c = 0; c < found && !held_there; ++c) held_there = s->found[c].vertex == now.vertex;
      if (!held_there) s->found[found++] = now;
    }
    // Bones first: a vertex a bone takes this round is no tool's.
    for (int c = 0; c < found; ++c) ++s->in_set[s->found[c].vertex];
    PenetrationSummary tool_summary;
    int tool_found = 0;
    if (tools != nullptr) {
      const int capacity =
          std::max(0, std::min(options_.max_tool_contacts - tool_held, k_max - set - found));
      tool_found = FindToolPenetrations(*tools, x, n, s->found.data() + found, capacity,
                                        &tool_summary, s->in_set.data());
    }
    for (int c = 0; c < found; ++c) --s->in_set[s->found[c].vertex];
    if (keeps_volume_ && round == 0 && set == 0 && found == 0 && tool_found == 0) {
      need_cubic();
      known_volume = cubic[0];
    }
    const double volume = std::isnan(known_volume) ? closure_->Volume(x) : known_volume;
    known_volume = std::numeric_limits<double>::quiet_NaN();
    if (round == 0) {
      report->before = summary;
      report->tool_before = tool_summary;
      report->volume_change_before = volume_change(volume);
    }
    report->after = summary;
    report->tool_after = tool_summary;
    report->volume_change_after = volume_change(volume);
    const bool volume_kept =
        !keeps_volume_ ||
        std::abs(volume - rest_volume_) <= options_.volume_tolerance * std::abs(rest_volume_);
    // The held tool contacts. Bones win: one pushed into a bone takes the bone's plane; one still
    // inside its tool gets the tool's plane at its new nearest point.
    for (int j = 0; j < set; ++j) {
      HeldContact& held = s->contacts[j];
      if (held.kind != ObstacleKind::kTool) continue;
      BonePenetration now;
      if (bones_ != nullptr && bones_->Deepest(held.at.vertex, x, frame->bone_transforms, &now)) {
        held.kind = ObstacleKind::kBone;
      } else if (!DeepestToolPenetration(*tools, held.at.vertex, x, &now)) {
        continue;
      }
      held.at.surface = now.surface;
      held.at.normal = now.normal;
      held.at.surface_point = now.surface_point;
      ++refreshed;
    }
    if ((found == 0 && tool_found == 0 && refreshed == 0 && volume_kept) ||
        round == options_.max_rounds) {
      break;
    }
    // With carried contacts, the first solve holds those alone: the skin they push out takes
    // its neighbours along, and the next round adds only what is still inside (adding every
    // vertex found at x* makes forward passes for contacts that then leave, every frame).
    const int bone_added = round == 0 && set > 0 && carried > 0 ? 0 : found;
    for (int c = 0; c < bone_added; ++c) ++s->in_set[s->found[c].vertex];
    for (int c = found; c < found + tool_found; ++c) ++s->in_set[s->found[c].vertex];
    if (bone_added > 0) AddContacts(factor, bone_added, ObstacleKind::kBone, s, report);
    if (tool_found > 0) {
      std::copy_n(s->found.begin() + found, tool_found, s->found.begin());
      AddContacts(factor, tool_found, ObstacleKind::kTool, s, report);
    }

    // The volume row: its gradient as the frame's bones turn the rest gradient, its direction
    // in the solve's metric, and its target relative to x*.
    bool volume_row = false;
    double volume_target = 0;
    if (keeps_volume_) {
      // g = sum_k h_ik R_k g_rest_i, its rows past the vertices (the joint nodes) zero
      // (MakeScratch). Before a round's first correction x is x*, and g . (x - x*) is 0.
      double moved = 0;
      if (round > 0) {
        if (!gradient_posed) {
          SumRotatedFields(gradient_fields_.data(), static_cast<std::size_t>(n),
                           static_cast<std::size_t>(n), static_cast<int>(direction_bones_.size()),
                           s->rotations.data(), s->gradient.data());
          gradient_posed = true;
        }
        for (std::size_t v = 0; v < values; ++v) moved += s->gradient[v] * (x[v] - s->base[v]);
      }
      volume_target = rest_volume_ - volume + moved;
      volume_row = gradient_dot_h > 0;
    }

    // The multipliers, dropping contacts that pull the skin inward until none does.
    const int stride = k_max + 1;
    double mu = 0;
    for (;;) {
      const int q = set + (volume_row ? 1 : 0);
      for (int l = 0; l < set; ++l) {
        const BonePenetration& cl = s->contacts[l].at;
        for (int j = 0; j <= l; ++j) {
          const double v = s->inverse_block[static_cast<std::size_t>(l) * k_max + j] *
                           cl.normal.dot(s->contacts[j].at.normal);
          s->system[l * stride + j] = v;
          s->system[j * stride + l] = v;
        }
        const double target = cl.normal.dot(cl.surface_point) + margin_;
        s->multipliers[l] = target - cl.normal.dot(Vec3(s->base.data() + 3 * cl.vertex));
        if (volume_row) {
          const double v = cl.normal.dot(Vec3(s->h.data() + 3 * cl.vertex));
          s->system[l * stride + set] = v;
          s->system[set * stride + l] = v;
        }
      }
      if (volume_row) {
        s->system[set * stride + set] = gradient_dot_h;
        s->multipliers[set] = volume_target;
      }
      if (q == 0) break;
      FactorSymmetric(s->system.data(), q, stride);
      SubstituteSymmetric(s->system.data(), q, stride, s->multipliers.data());
      mu = volume_row ? s->multipliers[set] : 0;
      // Drop every contact with a negative multiplier (from the end, swapping in the last).
      bool dropped = false;
      for (int j = set - 1; j >= 0; --j) {
        if (s->multipliers[j] >= 0) continue;
        dropped = true;
        const int last = set - 1;
        --s->in_set[s->contacts[j].at.vertex];
        if (j != last) {
          MoveContact(last, j, set, s);
          s->multipliers[j] = s->multipliers[last];
        }
        --set;
      }
      if (!dropped) break;
    }

    // x = x* + M^-1 sum_j lambda_j e_{i_j} n_j^T + mu M^-1 g.
    std::copy(s->base.begin(), s->base.end(), x);
    // With contacts and the volume row, the linearised mu leaves a fifth of a large volume
    // change, and a step along h alone would move the contacts off their planes. Along
    // d = h - M^-1 N nu, with A nu = N^T h (A the contact block, N the contacts' normals at their
    // vertices), the contacts stay on their planes (N^T d = 0), and x0 = x* + M^-1 N lambda0 with
    // lambda0 = lambda + mu nu holds them with the volume row's share taken out: the volume along
    // x0 + t d is a cubic in t, whose root next to mu keeps the rest volume exactly. Both
    // combinations are one six-column backward pass. The active set is the linearised row's: a
    // multiplier lambda0 - t nu that the exact t turns slightly negative holds its contact for
    // this frame, and the next frame, starting from it, drops it.
    const bool along_contacts = volume_row && set > 0;
    if (along_contacts) {
      for (int l = 0; l < set; ++l) {
        const BonePenetration& cl = s->contacts[l].at;
        s->shares[l] = cl.normal.dot(Vec3(s->h.data() + 3 * cl.vertex));
      }
      SubstituteSymmetric(s->system.data(), set, stride, s->shares.data());
      for (int l = 0; l < set; ++l) s->multipliers[l] += mu * s->shares[l];
    }
    if (set > 0) {
      // M^-1 e_i = P^T L^-T y_i: the contacts' forward passes are known, so the correction is
      // the backward pass of sum_j lambda_j y_j n_j^T (on their paths), half a solve.
      const int width = along_contacts ? 6 : 3;
      std::fill_n(s->correction.begin(), width * rows_, 0.0);
      for (int j = 0; j < set; ++j) {
        const BonePenetration& c = s->contacts[j].at;
        const Eigen::Vector3d weight = s->multipliers[j] * c.normal;
        const Eigen::Vector3d share =
            along_contacts ? Eigen::Vector3d(s->shares[j] * c.normal) : Eigen::Vector3d::Zero();
        const int* path = s->paths.data() + static_cast<std::size_t>(j) * path_supernodes_;
        const double* y = s->path_values.data() + static_cast<std::size_t>(j) * path_columns_;
        for (int p = 0; p < s->path_lengths[j]; ++p) {
          const int columns = factor.SupernodeWidth(path[p]);
          double* z = s->correction.data() +
                      static_cast<std::size_t>(width) * factor.SupernodeFirstColumn(path[p]);
          for (int q = 0; q < columns; ++q) {
            double* zq = z + width * q;
            zq[0] += weight.x() * y[q];
            zq[1] += weight.y() * y[q];
            zq[2] += weight.z() * y[q];
            if (along_contacts) {
              zq[3] += share.x() * y[q];
              zq[4] += share.y() * y[q];
              zq[5] += share.z() * y[q];
            }
          }
          y += columns;
        }
      }
      ++report->backward_passes;
      if (along_contacts) {
        Solved(factor.SolveBackwardMany(s->correction.data(), s->correction.data(), 6,
                                        s->solve_work.data()));
        const double* c = s->correction.data();
        for (int r = 0; r < rows_; ++r) {
          for (int k = 0; k < 3; ++k) {
            x[3 * r + k] += c[6 * r + k];
            s->direction[3 * r + k] = s->h[3 * r + k] - c[6 * r + 3 + k];
          }
        }
      } else {
        Solved(factor.SolveBackward3(s->correction.data(), s->correction.data(),
                                     s->solve_work.data()));
        for (std::size_t v = 0; v < values; ++v) x[v] += s->correction[v];
      }
    }
    if (along_contacts) {
      double along[4];
      closure_->VolumeAlong(x, s->direction.data(), along);
      const double t = CubicRoot(along, rest_volume_, mu);
      for (std::size_t v = 0; v < values; ++v) x[v] += t * s->direction[v];
      known_volume = CubicAt(along, t);
    } else if (volume_row) {
      // The volume alone: along x* + mu h it is a cubic in mu, so take its root next to the
      // linearised mu and the volume is kept in this round, not the next.
      need_cubic();
      mu = CubicRoot(cubic, rest_volume_, mu);
      known_volume = CubicAt(cubic, mu);
      for (std::size_t v = 0; v < values; ++v) x[v] += mu * s->h[v];
    }
    ++report->rounds;
  }
  report->unresolved = report->after.vertices > 0;
  report->tools_unresolved = report->tool_after.vertices > 0;
  report->carried_contacts = carried;
  // The bone contacts stay for the next frame; the tool contacts leave (a tool moves on its own).
  for (int j = set - 1; j >= 0; --j) {
    if (s->contacts[j].kind != ObstacleKind::kTool) continue;
    ++report->tool_contacts;
    --s->in_set[s->contacts[j].at.vertex];
    if (j != set - 1) MoveContact(set - 1, j, set, s);
    --set;
  }
  s->kept = set;
  s->kept_serial = factorization.serial();
  // Contacts of the last solve; none when the frame needed no solve.
  if (report->rounds == 0)
    report->contacts = 0;
  else
    report->contacts += report->tool_contacts;
  return true;
}

}  // namespace deform
