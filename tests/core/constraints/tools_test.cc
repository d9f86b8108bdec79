#include "core/constraints/tools.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "core/constraints/skin_constraints.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "tests/allocation_counter.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

// The phantom with its bones, and constraints with their defaults.
struct Limb {
  std::shared_ptr<const DeformationModel> model;
  std::shared_ptr<const BoneContacts> bones;
  std::shared_ptr<const SkinConstraints> constraints;
  double diagonal = 0;
};

Limb PhantomLimb(int vertices = 2000, const ConstraintOptions& options = {}) {
  KneePhantom phantom = *MakeKneePhantom(vertices);
  Limb limb;
  limb.model = *DeformationModel::Build(phantom.mesh, phantom.skeleton, ModelOptions::Paper());
  limb.bones = *BoneContacts::Create(phantom.bones, phantom.skeleton, phantom.mesh,
                                     limb.model->rigid_bones());
  limb.constraints = *SkinConstraints::Create(*limb.model, limb.bones, options);
  limb.diagonal = limb.model->bounding_box_diagonal();
  return limb;
}

Pose PoseFrom(const Skeleton& skeleton, const std::string& spec) {
  Pose pose;
  EXPECT_TRUE(PoseFromTerms(skeleton, *ParsePoseSpec(spec, skeleton), &pose).ok());
  return pose;
}

// One frame of `pose` with `tools` (null: none) through `scratch`.
Positions Solve(const Limb& limb, const Pose& pose, const ToolSet* tools,
                ConstraintScratch* scratch, ConstraintReport* report) {
  const DeformationModel& model = *limb.model;
  DeformScratch frame = model.MakeScratch();
  EXPECT_TRUE(model.Deform(*model.default_factorization(), pose, &frame));
  EXPECT_TRUE(
      limb.constraints->Apply(*model.default_factorization(), &frame, scratch, report, tools));
  return frame.positions();
}

// A sphere of `radius` pressed `depth` into the skin from the front (+z) at height y, on the
// frame `free` (the skin's vertex there with its outward, horizontal normal).
Tool PressedSphere(const Positions& free, double y, double radius, double depth) {
  int best = -1;
  for (int i = 0; i < free.rows(); ++i) {
    if (std::abs(free(i, 1) - y) > 0.1) continue;
    if (best < 0 || free(i, 2) > free(best, 2)) best = i;
  }
  const Eigen::Vector3d p = free.row(best).transpose();
  const Eigen::Vector3d normal = Eigen::Vector3d(p.x(), 0, p.z()).normalized();
  Tool tool;
  tool.radius = radius;
  tool.a = p + (radius - depth) * normal;
  return tool;
}

// The deepest skin vertex inside any tool.
double DeepestInside(const ToolSet& tools, const Positions& x) {
  PenetrationSummary summary;
  FindToolPenetrations(tools, x.data(), static_cast<int>(x.rows()), nullptr, 0, &summary);
  return summary.max_depth;
}

// The phantom (diagonal about 9 units) with a sphere of radius 0.3 pressed 0.1 into the front of
// the thigh: about a centimetre into a leg 9 decimetres long.
TEST(Tools, ASpherePressedIntoTheSkinLeavesNoVertexInsideAndADentThatFades) {
  const Limb limb = PhantomLimb();
  const Pose pose = PoseFrom(limb.model->skeleton(), "knee:flexion:30");
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  ConstraintReport report;
  const Positions free = Solve(limb, pose, nullptr, &scratch, &report);
  ToolSet tools;
  ASSERT_TRUE(tools.Add(PressedSphere(free, 6.0, 0.3, 0.1)));
  ASSERT_GT(DeepestInside(tools, free), 0.09);

  const Positions pressed = Solve(limb, pose, &tools, &scratch, &report);
  EXPECT_GT(report.tool_before.vertices, 0);
  EXPECT_GT(report.tool_contacts, 0);
  EXPECT_LE(report.tool_contacts, ConstraintOptions().max_tool_contacts);
  EXPECT_FALSE(report.tools_unresolved);
  EXPECT_FALSE(report.unresolved);
  EXPECT_LE(DeepestInside(tools, pressed) / limb.diagonal, 1e-4);
  EXPECT_EQ(report.tool_after.vertices, 0);
  EXPECT_LE(std::abs(report.volume_change_after), 1e-4);

  // The displacement falls with the distance from the tool's surface (in the tool-free frame):
  // the vertices the tool would penetrate move by up to its depth, every vertex outside it by less
  // than 1e-3 of the diagonal (the volume kept spreads the dent's volume over the blend regions,
  // the rest is the dent's own tail), and those beyond 0.2 units (2.2% of the diagonal, about one
  // ring of the phantom) by less than 1e-5 of it.
  const Tool& tool = tools.tools[0];
  double inside = 0, outside = 0, near = 0, far = 0;
  for (int i = 0; i < free.rows(); ++i) {
    const double distance = (free.row(i).transpose() - tool.a).norm() - tool.radius;
    const double moved = (pressed.row(i) - free.row(i)).norm();
    if (distance <= 0) inside = std::max(inside, moved);
    if (distance > 0) outside = std::max(outside, moved);
    if (distance > 0 && distance <= 0.2) near = std::max(near, moved);
    if (distance > 0.2 && distance <= 1.0) far = std::max(far, moved);
  }
  EXPECT_GT(inside / limb.diagonal, 5e-3);
  EXPECT_LT(outside / limb.diagonal, 1e-3);
  EXPECT_LT(far / limb.diagonal, 1e-5);
  EXPECT_LT(far, near);
  EXPECT_LT(near, inside);

  // Lifting the tool gives back the tool-free frame, bit for bit, through the same scratch.
  const Positions lifted = Solve(limb, pose, nullptr, &scratch, &report);
  EXPECT_EQ((lifted - free).cwiseAbs().maxCoeff(), 0);
  EXPECT_EQ(report.tool_contacts, 0);
  ToolSet empty;
  const Positions none = Solve(limb, pose, &empty, &scratch, &report);
  EXPECT_EQ((none - free).cwiseAbs().maxCoeff(), 0);
}

TEST(Tools, ACapsuleAndTwoToolsAreHeldOut) {
  const Limb limb = PhantomLimb();
  const Pose pose = PoseFrom(limb.model->skeleton(), "knee:flexion:60");
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  ConstraintReport report;
  const Positions free = Solve(limb, pose, nullptr, &scratch, &report);
  ToolSet tools;
  Tool capsule = PressedSphere(free, 6.5, 0.15, 0.05);
  capsule.shape = Tool::Shape::kCapsule;
  capsule.b = capsule.a + Eigen::Vector3d(0.4, 0, 0);
  capsule.a -= Eigen::Vector3d(0.4, 0, 0);
  ASSERT_TRUE(tools.Add(capsule));
  ASSERT_TRUE(tools.Add(PressedSphere(free, 5.6, 0.2, 0.06)));
  ASSERT_GT(DeepestInside(tools, free), 0.04);
  const Positions pressed = Solve(limb, pose, &tools, &scratch, &report);
  EXPECT_FALSE(report.tools_unresolved);
  EXPECT_LE(DeepestInside(tools, pressed) / limb.diagonal, 1e-4);
  EXPECT_EQ(report.after.vertices, 0);
}

TEST(Tools, BonesWinOverATool) {
  // A sphere pushed through the skin down to the femur: the skin stays outside the bone and what
  // is left inside the tool is reported.
  const Limb limb = PhantomLimb(800);
  const Pose pose = Pose::Rest(limb.model->skeleton());
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  ConstraintReport report;
  const Positions free = Solve(limb, pose, nullptr, &scratch, &report);
  ToolSet tools;
  ASSERT_TRUE(tools.Add(PressedSphere(free, 6.0, 2.0, 0.6)));
  const Positions pressed = Solve(limb, pose, &tools, &scratch, &report);
  EXPECT_EQ(report.after.vertices, 0);
  EXPECT_TRUE(report.tools_unresolved);
  EXPECT_GT(report.tool_after.vertices, 0);
  std::vector<RigidTransform> bones;
  ForwardKinematics(limb.model->skeleton(), pose, &bones);
  EXPECT_EQ(limb.bones->Measure(pressed, bones).vertices, 0);
}

// The 26k leg (diagonal 9.6 units for a leg about 1.1 m long: a unit is about 11 cm) with its
// capsule bones, the knee moving through 0, 30, 60 and 90 degrees with a sphere of radius 0.17
// (about 2 cm) pressed 0.087 (about 1 cm) into the front of the thigh: no skin vertex inside the
// tool by more than 1e-4 of the diagonal, none inside a bone, every vertex outside the tool moved
// by less than 1e-3 of the diagonal, and each frame without the tool is the tool-free frame.
TEST(Tools, ASpherePressedIntoThe26kLegWhileTheKneeMoves) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "leg/leg_25969.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "leg/leg.tgf");
  const TriangleMesh mesh = *ReadMeshFile(mesh_path);
  const Skeleton skeleton = *ReadSkeletonFile(skeleton_path);
  Limb limb;
  limb.model = *DeformationModel::Build(mesh, skeleton, ModelOptions::Paper());
  limb.bones = *BoneContacts::Create(MakeCapsuleBoneSurfaces(mesh, skeleton), skeleton, mesh,
                                     limb.model->rigid_bones());
  limb.constraints = *SkinConstraints::Create(*limb.model, limb.bones);
  limb.diagonal = limb.model->bounding_box_diagonal();
  ToolSet tools;
  Tool sphere;
  sphere.a = Eigen::Vector3d(1.44, -1.72, 1.201);
  sphere.radius = 0.17;
  ASSERT_TRUE(tools.Add(sphere));
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  for (const char* degrees : {"0", "30", "60", "90"}) {
    SCOPED_TRACE(degrees);
    const Pose pose = PoseFrom(skeleton, std::string("1:x:") + degrees);
    ConstraintReport report;
    const Positions free = Solve(limb, pose, nullptr, &scratch, &report);
    ASSERT_GT(DeepestInside(tools, free) / limb.diagonal, 5e-3);
    const Positions pressed = Solve(limb, pose, &tools, &scratch, &report);
    EXPECT_LE(DeepestInside(tools, pressed) / limb.diagonal, 1e-4);
    EXPECT_FALSE(report.tools_unresolved);
    EXPECT_EQ(report.after.vertices, 0);
    double outside = 0;
    for (int i = 0; i < free.rows(); ++i) {
      if ((free.row(i).transpose() - sphere.a).norm() <= sphere.radius) continue;
      outside = std::max(outside, (pressed.row(i) - free.row(i)).norm());
    }
    EXPECT_LT(outside / limb.diagonal, 1e-3);
    const Positions lifted = Solve(limb, pose, nullptr, &scratch, &report);
    EXPECT_EQ((lifted - free).cwiseAbs().maxCoeff(), 0);
  }
}

TEST(Tools, ApplyWithToolsAllocatesNothing) {
  const Limb limb = PhantomLimb(800);
  const DeformationModel& model = *limb.model;
  const Pose pose = PoseFrom(model.skeleton(), "knee:flexion:90");
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  ConstraintReport report;
  const Positions free = Solve(limb, pose, nullptr, &scratch, &report);
  ToolSet tools;
  ASSERT_TRUE(tools.Add(PressedSphere(free, 6.0, 0.3, 0.1)));
  DeformScratch frame = model.MakeScratch();
  ASSERT_TRUE(model.Deform(*model.default_factorization(), pose, &frame));
  ASSERT_TRUE(
      limb.constraints->Apply(*model.default_factorization(), &frame, &scratch, &report, &tools));
  const long before = test_support::AllocationCount();
  ASSERT_TRUE(model.Deform(*model.default_factorization(), pose, &frame));
  ASSERT_TRUE(
      limb.constraints->Apply(*model.default_factorization(), &frame, &scratch, &report, &tools));
  EXPECT_EQ(test_support::AllocationCount() - before, 0);
  EXPECT_GT(report.tool_contacts, 0);
}

TEST(Tools, ConstraintsThatTakeNoToolsRefuseThem) {
  ConstraintOptions options;
  options.max_tool_contacts = 0;
  const Limb limb = PhantomLimb(800, options);
  EXPECT_FALSE(limb.constraints->takes_tools());
  const DeformationModel& model = *limb.model;
  DeformScratch frame = model.MakeScratch();
  ASSERT_TRUE(model.Deform(*model.default_factorization(), Pose::Rest(model.skeleton()), &frame));
  ConstraintScratch scratch = limb.constraints->MakeScratch();
  ConstraintReport report;
  ToolSet tools;
  Tool tool;
  tool.radius = 0.1;
  ASSERT_TRUE(tools.Add(tool));
  EXPECT_FALSE(
      limb.constraints->Apply(*model.default_factorization(), &frame, &scratch, &report, &tools));
  options.max_tool_contacts = ConstraintOptions::kMaxToolContacts + 1;
  EXPECT_FALSE(SkinConstraints::Create(model, nullptr, options).ok());
}

TEST(Tools, ValidationRefusesBadTools) {
  const Eigen::Vector3d lower(0, 0, 0), upper(1, 1, 1);  // diagonal sqrt(3)
  Tool good;
  good.a = Eigen::Vector3d(0.5, 0.5, 1.2);
  good.radius = 0.1;
  EXPECT_TRUE(ValidateTool(good, 0, lower, upper).ok());
  Tool bad = good;
  bad.radius = 0;
  EXPECT_FALSE(ValidateTool(bad, 0, lower, upper).ok());
  bad.radius = 1;  // more than half the diagonal
  EXPECT_FALSE(ValidateTool(bad, 0, lower, upper).ok());
  bad = good;
  bad.a.x() = std::numeric_limits<double>::quiet_NaN();
  const Status status = ValidateTool(bad, 2, lower, upper);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("tool 2"), std::string::npos);
  bad = good;
  bad.a.y() = 100;
  EXPECT_FALSE(ValidateTool(bad, 0, lower, upper).ok());
  bad = good;
  bad.shape = Tool::Shape::kCapsule;
  bad.b = Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0);
  EXPECT_FALSE(ValidateTool(bad, 0, lower, upper).ok());
  ToolSet set;
  for (int t = 0; t < ToolSet::kMaxTools; ++t) EXPECT_TRUE(set.Add(good));
  EXPECT_FALSE(set.Add(good));
  EXPECT_TRUE(ValidateToolSet(set, lower, upper).ok());
}

TEST(Tools, PenetrationOfASphereAndACapsule) {
  Tool sphere;
  sphere.radius = 1;
  BonePenetration p;
  ASSERT_TRUE(ToolPenetration(sphere, Eigen::Vector3d(0, 0.25, 0), &p));
  EXPECT_DOUBLE_EQ(p.depth, 0.75);
  EXPECT_TRUE(p.normal.isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(p.surface_point.isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_FALSE(ToolPenetration(sphere, Eigen::Vector3d(0, 1.5, 0), &p));
  Tool capsule = sphere;
  capsule.shape = Tool::Shape::kCapsule;
  capsule.b = Eigen::Vector3d(2, 0, 0);
  ASSERT_TRUE(ToolPenetration(capsule, Eigen::Vector3d(1.5, 0, -0.5), &p));
  EXPECT_DOUBLE_EQ(p.depth, 0.5);
  EXPECT_TRUE(p.normal.isApprox(-Eigen::Vector3d::UnitZ()));
  ASSERT_TRUE(ToolPenetration(capsule, Eigen::Vector3d(1, 0, 0), &p));  // on the axis
  EXPECT_DOUBLE_EQ(p.depth, 1);
  EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
  EXPECT_NEAR(p.normal.x(), 0, 1e-12);
}

}  // namespace
}  // namespace deform
