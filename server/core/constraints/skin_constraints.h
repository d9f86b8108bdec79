// Conditions on the whole skin that a frame's solve meets (METHOD.md, "Constraints the solve can
// take"): skin kept outside the bone surfaces, and the enclosed volume kept.
//
// Applied after any of the model's solving paths (Deform, DeformBatch, their parallel forms, the
// linear response) to the frame in a DeformScratch, with the same factorization: the frame x* is
// the unconstrained minimiser of the model's energy |A x - b|^2, so the constrained frame is
//
//   x = argmin (x - x*)^T M (x - x*)  subject to  n_j . x_{i_j} = d_j        (contacts, j < k)
//                                                 g . (x - x_c) = V_rest - V(x_c)  (volume)
//
// (x_c the frame of the previous round, x* in the first). The volume's gradient g is taken as the
// frame's bones turn the rest gradient (g_i = sum_k h_ik R_k g_rest_i on the vertices outside the
// rigid zones, zero on them), so that its direction in the solve's metric is
// M^-1 g = sum_k D_k R_k^T with D_k = M^-1 (h_k g_rest) solved once for the model's default
// factorization, here, and read by every stream (another stiffness: once per stream and
// factorization): no solve per frame. Without contacts the volume along x* + mu M^-1 g is a cubic
// in mu, solved exactly, so the volume is kept in one round. With contacts the linearised row
// decides which contacts stay, and the step is exact along d = M^-1 g - M^-1 N nu (A nu = N^T M^-1
// g, A the contacts' block, N their normals), which leaves every contact on its plane (N^T d = 0):
// the volume along it is a cubic again. The contacts' correction and d's are one six-column
// backward pass (CholeskyFactor::SolveBackwardMany), so a frame whose contacts hold needs one
// round.
//
// With M = A^T A = P^T L L^T P, the one factorization: x = x* + sum_j lambda_j M^-1 e_{i_j} n_j^T +
// mu M^-1 g. The contacts need (M^-1)_{i_l i_j} = y_l . y_j with y_j = L^-1 P e_{i_j}, each a
// forward pass along one path of the elimination tree (CholeskyFactor::ForwardUnitSolves, a
// round's paths together: a fraction of a solve), then a (k + 1)-square dense system and, for the
// correction P^T L^-T sum_j lambda_j y_j n_j^T, one backward pass (half a solve: the forward half
// is the y_j already made): low-rank terms on the one factorization, never a
// refactorization. Contacts come from an active set: solve, find the vertices inside a bone, hold
// each on its nearest surface point's tangent plane (plus a margin), solve again; a contact whose
// multiplier pulls the skin inward leaves the set, and a held vertex still inside gets the tangent
// plane of its new nearest point. A vertex is held out of the deeper bone first; one the solve
// then pushes into another bone gets a second contact, there, so skin caught between two bones is
// held out of both.
//
// A scratch carries a frame's bone contacts into the next frame (a stream's frames follow each
// other): y_j and the inverse block depend only on the vertex and the factorization, so a contact
// that persists costs no forward pass again. Each carried contact starts with its plane at the
// new frame's nearest bone point, inside or not; one the frame does not need gets a negative
// multiplier and leaves. The solution is the same optimum as a fresh active set's up to where a
// plane was taken; a new factorization (a stiffness change) drops them.
//
// Bones and tools (tools.h) are both obstacles of that one active set, each contact tagged with
// its kind: a skin vertex inside a tool is held on the tool's tangent plane at its nearest surface
// point (plus the same margin), so the skin slides on the tool. Bones win: a vertex inside a bone
// and a tool is held out of the bone, and a tool contact whose vertex the solve pushes into a bone
// takes the bone's plane; what is left inside a tool is reported (tool_after, tools_unresolved).
// Each kind has its own bound on contacts (max_contacts, max_tool_contacts), so a tool cannot
// take the bones' budget. Without tools (none given, or an empty set) Apply computes exactly the
// tool-free frame: nothing of a tool enters the arithmetic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/constraints/bone_contacts.h"
#include "core/constraints/tools.h"
#include "core/geometry/volume_closure.h"
#include "core/model/deformation_model.h"

namespace deform {

struct ConstraintOptions {
  // Contacts hold the skin this far outside a bone surface, as a fraction of the skin's
  // bounding-box diagonal. Default: 1e-3.
  double contact_margin = 1e-3;
  // At most this many contact constraints in a frame (the k of the low-rank terms); a frame that
  // needs more is flagged unresolved. In [0, kMaxContacts], or kAutomaticContacts (the default):
  // AutomaticMaxContacts of the skin's vertex count.
  int max_contacts = kAutomaticContacts;
  static constexpr int kMaxContacts = 2048;
  static constexpr int kAutomaticContacts = -1;
  // The automatic bound: one contact per kVerticesPerContact skin vertices, at least
  // kMinAutomaticContacts, at most kMaxContacts. The skin a bone presses on grows with the
  // mesh's density (the 133k arm at 120 degrees needs 573 contacts, the 1.6k leg a handful), and
  // a per-frame bound of the same size for every mesh leaves a dense one inside its bones.
  static constexpr int kVerticesPerContact = 128;
  static constexpr int kMinAutomaticContacts = 128;
  static int AutomaticMaxContacts(int vertices);
  // Whether skin is held outside the bones (max_contacts 0: penetrations are measured only).
  bool contacts() const { return max_contacts != 0; }
  // At most this many tool contacts in a frame, besides max_contacts, so that a tool never takes
  // the bones' budget (docs/instruments.md). 0: tools are refused. In [0, kMaxToolContacts].
  // Default: 64.
  int max_tool_contacts = 64;
  static constexpr int kMaxToolContacts = 256;
  // Keep the enclosed volume of the skin (an open skin closed by a fan at each boundary loop)
  // within volume_tolerance of its rest volume, relative. Default: on.
  bool keep_volume = true;
  double volume_tolerance = 1e-4;
  // Rounds of the active set (each: find contacts, solve). In [1, 16]. Default: 8.
  int max_rounds = 8;
  // With contacts: the skin a bone surface reaches across a joint within its range of motion is
  // solved rather than anchored (UnanchorReachedSkin, bone_reach.h, applied before the model is
  // built), so contacts move it without pulling a rigid zone off its bone. Default: on.
  bool bone_reach = true;
};

// What the constraints did to one frame.
struct ConstraintReport {
  PenetrationSummary before;  // the frame as the model solved it
  PenetrationSummary after;   // the frame returned
  int contacts = 0;           // contact constraints in the last solve
  int rounds = 0;             // constrained solves
  int solves = 0;             // three-column solves with the factor (a frame's is one)
  int backward_passes = 0;    // backward halves of a solve (SolveBackward3), one a round
  int unit_solves = 0;        // unit right-hand sides (ForwardUnitSolves), one a new contact
  // Bone contacts carried over from the scratch's last frame (their forward passes and products
  // kept, not redone).
  int carried_contacts = 0;
  // Vertices left inside a bone (more contacts than max_contacts, or rounds exhausted).
  bool unresolved = false;
  double volume_change_before = 0;  // (V - V_rest) / V_rest
  double volume_change_after = 0;
  // Skin inside a tool: before (the model's frame) and after, model units; the tool contacts of
  // the last solve (counted in `contacts` too); vertices left inside a tool (bones won, more than
  // max_tool_contacts, or rounds exhausted).
  PenetrationSummary tool_before;
  PenetrationSummary tool_after;
  int tool_contacts = 0;
  bool tools_unresolved = false;
};

// What holds a contact's vertex: a bone surface or a tool (the contact's `surface` indexes
// BoneContacts' surfaces or the frame's ToolSet).
enum class ObstacleKind : std::uint8_t { kBone, kTool };
struct HeldContact {
  BonePenetration at;
  ObstacleKind kind = ObstacleKind::kBone;
};

// Per-caller buffers of Apply; one per stream, made by MakeScratch.
struct ConstraintScratch {
 private:
  friend class SkinConstraints;
  std::vector<double> base;      // x*, (n + m) by 3
  std::vector<double> gradient;  // g, (n + m) by 3 (zero on the joint nodes' and rigid rows)
  std::vector<double> h;         // M^-1 g
  // D_k (SkinConstraints::default_directions_) for a factorization other than the model's
  // default (a stiffness change), the one with this serial (MaterialFactorization::serial; 0:
  // none yet): solved by the stream's first frame on it.
  std::vector<float> bone_directions;
  std::vector<Eigen::Matrix3d> direction_products;  // their GradientProducts
  std::uint64_t directions_serial = 0;
  std::vector<Eigen::Matrix3d> rotations;  // the frame's rotations of the direction bones
  // Right-hand side, then M^-1 sum lambda_j e_{i_j} n_j^T; with the volume, beside it (six
  // columns a row) M^-1 sum nu_j e_{i_j} n_j^T.
  std::vector<double> correction;
  std::vector<double> direction;  // d = h - M^-1 N nu, the volume's step that keeps the contacts
  std::vector<double> shares;     // nu: A nu = N^T h, the contacts' share of the volume's step
  std::vector<double> unit_work;  // ForwardUnitSolves', zeros
  std::vector<int> unit_columns;  // a round's new contacts' vertices
  std::vector<int> paths;         // per contact, its path's supernodes (path_supernodes each)
  std::vector<int> path_lengths;
  std::vector<double> path_values;  // per contact, y on its path (path_columns each)
  std::vector<double> solve_work;
  std::vector<BonePenetration> found;  // a round's new bone contacts, then its tool contacts
  std::vector<HeldContact> contacts;
  std::vector<double> inverse_block;  // (M^-1)_{i_l i_j}, (max_contacts + max_tool_contacts) square
  std::vector<double> system;         // the (k + 1)-square system, then its Cholesky factor
  std::vector<double> multipliers;    // its right-hand side, then lambda and mu
  // Per vertex: the contacts that hold it, at most one a bone surface (BoneSurfaceLimits: 64).
  std::vector<char> in_set;
  // The last frame's bone contacts, contacts[0, kept), for its factorization's serial.
  int kept = 0;
  std::uint64_t kept_serial = 0;
  const void* owner = nullptr;
};

class SkinConstraints {
 public:
  // Constraints for frames of `model` (which must outlive them). `bones` may be null (no
  // contacts). INVALID_ARGUMENT for options out of range.
  static StatusOr<std::shared_ptr<const SkinConstraints>> Create(
      const DeformationModel& model, std::shared_ptr<const BoneContacts> bones,
      const ConstraintOptions& options = {});

  ConstraintScratch MakeScratch() const;
  // The bytes MakeScratch allocates.
  std::size_t ScratchBytes() const;

  // Constrains the frame in `frame` (solved by the model with `factorization`; its
  // bone_transforms are the frame's) in place, with the frame's `tools` (may be null: none;
  // validated by the caller, ValidateToolSet). Allocation-free. False, with nothing changed, for
  // another model's factorization or scratch, another constraints' scratch, or tools given to
  // constraints that take none (max_tool_contacts 0).
  bool Apply(const MaterialFactorization& factorization, DeformScratch* frame,
             ConstraintScratch* scratch, ConstraintReport* report,
             const ToolSet* tools = nullptr) const;

  // Whether Apply ever changes a frame without tools.
  bool active() const { return bones_ != nullptr || keeps_volume_; }
  // Whether Apply takes tools (max_tool_contacts > 0).
  bool takes_tools() const { return options_.max_tool_contacts > 0; }
  const BoneContacts* bones() const { return bones_.get(); }
  const std::shared_ptr<const BoneContacts>& bones_shared() const { return bones_; }
  const ConstraintOptions& options() const { return options_; }
  double rest_volume() const { return rest_volume_; }

 private:
  SkinConstraints() = default;
  // Contacts the scratch holds: max_contacts with bones, plus max_tool_contacts.
  int ContactCapacity() const;
  // Adds the contacts found[0, count) of `kind` to the set and fills their rows and columns of the
  // inverse block from their paths.
  void AddContacts(const CholeskyFactor& factor, int count, ObstacleKind kind, ConstraintScratch* s,
                   ConstraintReport* report) const;
  // y_l . y_j of two contacts' paths.
  double PathDot(const CholeskyFactor& factor, const ConstraintScratch& s, int l, int j) const;
  // Moves contact `from` to slot `to` (its path and its row and column of the inverse block).
  void MoveContact(int from, int to, int set, ConstraintScratch* s) const;
  // The frame's volume direction M^-1 g (into s->h), from the bone directions (solved first when
  // the scratch holds another factorization's), and the rotations that pose g (s->rotations).
  // Returns the frame's g . M^-1 g; g itself is posed only when a round needs it (contacts).
  double PoseVolumeDirections(const MaterialFactorization& factorization,
                              const std::vector<RigidTransform>& bones, ConstraintScratch* s,
                              ConstraintReport* report) const;
  // D_k = M^-1 (h_k g_rest) of every direction bone with `factorization` into `directions`
  // ((n + m) by 3 each, by coordinate), through `column` (3 (n + m) doubles) and the solve's
  // `work`; returns the solves made.
  int SolveBoneDirections(const MaterialFactorization& factorization, float* directions,
                          double* column, double* work) const;
  // C_kl = sum_i D_l,i (h_ik g_rest_i)^T over the vertices, for every pair of direction bones
  // (k major): g . M^-1 g = sum_kl tr(R_k^T R_l C_kl), a frame's volume row without a pass over
  // the rows, so that a frame without contacts never poses g.
  void GradientProducts(const float* directions, Eigen::Matrix3d* products) const;
  // g . M^-1 g of the frame whose direction bones turn by `rotations`.
  double GradientDotDirection(const Eigen::Matrix3d* products,
                              const Eigen::Matrix3d* rotations) const;

  const DeformationModel* model_ = nullptr;
  std::shared_ptr<const BoneContacts> bones_;
  ConstraintOptions options_;
  std::unique_ptr<VolumeClosure> closure_;
  std::vector<char> volume_free_;     // per vertex: carries the volume gradient (not a rigid zone)
  std::vector<int> direction_bones_;  // bones that weigh a free vertex
  // h_ik g_rest_i for each direction bone k, n by 3 each, by coordinate (SumRotatedFields'). In
  // float like the directions: g only linearises the volume, whose step is then exact.
  std::vector<float> gradient_fields_;
  // D_k = M^-1 (h_k g_rest) per direction bone with the model's default factorization, (n + m)
  // by 3 each, by coordinate (SumRotatedFields' layout), solved once here and read by every
  // stream: so many streams' frames pose one cache-resident copy, not one each. In float: h is a
  // direction, and every use of it reads the same rounded h (the contacts' shares, the exact
  // volume step), so its rounding only tilts the step by 1e-7, and posing it streams half the
  // bytes.
  std::vector<float> default_directions_;
  std::vector<Eigen::Matrix3d> default_products_;  // their GradientProducts
  std::uint64_t default_serial_ = 0;
  double rest_volume_ = 0;
  bool keeps_volume_ = false;
  double margin_ = 0;  // model units
  int rows_ = 0;       // n + m
  // The longest path of the factor's elimination tree (CholeskyFactor::LongestUnitSolvePath).
  std::int64_t path_columns_ = 0;
  int path_supernodes_ = 0;
};

}  // namespace deform
