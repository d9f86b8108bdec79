#include "core/constraints/tool_contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "tests/allocation_counter.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

// A closed, outward-oriented octahedron of "radius" 1 around the origin.
TriangleMesh Octahedron() {
  TriangleMesh mesh;
  mesh.vertices.resize(6, 3);
  mesh.vertices << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  mesh.triangles.resize(8, 3);
  mesh.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return mesh;
}

Tool Sphere(const Eigen::Vector3d& centre, double radius) {
  Tool tool;
  tool.a = tool.b = centre;
  tool.radius = radius;
  return tool;
}

Tool Capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  Tool tool;
  tool.shape = Tool::Shape::kCapsule;
  tool.a = a;
  tool.b = b;
  tool.radius = radius;
  return tool;
}

TEST(SkinContactQuery, ASphereOutsideACornerIsApartUntilItsRadiusReachesIt) {
  const auto query = SkinContactQuery::Create(Octahedron(), {}).value();
  const ContactForceModel model;
  const SkinContact apart = query->Query(Sphere({2, 0, 0}, 0.5), model);
  EXPECT_TRUE(apart.point.isApprox(Eigen::Vector3d(1, 0, 0)));
  // At the corner: the angle-weighted pseudo-normal, +x by symmetry.
  EXPECT_TRUE(apart.normal.isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  EXPECT_NEAR(apart.signed_distance, 1, 1e-12);
  EXPECT_EQ(apart.depth, 0);
  EXPECT_EQ(apart.force.norm(), 0);

  const SkinContact pressing = query->Query(Sphere({2, 0, 0}, 1.5), model);
  EXPECT_NEAR(pressing.depth, 0.5, 1e-12);
  EXPECT_NEAR(pressing.material_weight, 1, 1e-12);
  const double diagonal = 2 * std::sqrt(3.0);
  EXPECT_TRUE(pressing.force.isApprox(Eigen::Vector3d(model.stiffness * 0.5 / diagonal, 0, 0)));
}

TEST(SkinContactQuery, TheEdgeAndFaceNormalsSignTheDistance) {
  const auto query = SkinContactQuery::Create(Octahedron(), {}).value();
  // Beyond the edge between the +x and +y corners (z = 0): the edge's pseudo-normal.
  const SkinContact edge = query->Query(Sphere({0.8, 0.8, 0}, 0.1), {});
  EXPECT_TRUE(edge.point.isApprox(Eigen::Vector3d(0.5, 0.5, 0)));
  EXPECT_TRUE(edge.normal.isApprox(Eigen::Vector3d(1, 1, 0).normalized(), 1e-9));
  EXPECT_NEAR(edge.signed_distance, std::sqrt(0.18), 1e-12);
  // Inside: the centre's distance to a face is 1 / sqrt(3), negative.
  const SkinContact inside = query->Query(Sphere({0, 0, 0}, 0.1), {});
  EXPECT_NEAR(inside.signed_distance, -1 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(inside.depth, 0.1 + 1 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(std::abs(inside.normal.dot(Eigen::Vector3d::Ones().normalized())), 1, 1e-12);
}

TEST(SkinContactQuery, ACapsuleTakesItsAxisPointNearestTheSkin) {
  const auto query = SkinContactQuery::Create(Octahedron(), {}).value();
  // Parallel to the y axis above the +z corner, its nearest axis point at (0, 0, 1.5).
  const SkinContact contact = query->Query(Capsule({0, -1, 1.5}, {0, 1, 1.5}, 0.6), {});
  EXPECT_TRUE(contact.point.isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_NEAR(contact.tool_point.z(), 1.5, 1e-12);
  EXPECT_NEAR(contact.tool_point.y(), 0, 1e-12);
  EXPECT_NEAR(contact.depth, 0.1, 1e-12);
  EXPECT_GT(contact.force.z(), 0);
  // Through the skin: distance 0, depth the radius.
  const SkinContact through = query->Query(Capsule({0, 0, 0}, {0, 0, 3}, 0.2), {});
  EXPECT_NEAR(through.signed_distance, 0, 1e-12);
  EXPECT_NEAR(through.depth, 0.2, 1e-12);
}

TEST(SkinContactQuery, TheForceScalesWithTheMaterialWeightAtThePoint) {
  std::vector<double> weights(6, 1.0);
  weights[0] = 3;  // the +x corner
  const auto query = SkinContactQuery::Create(Octahedron(), weights).value();
  const SkinContact at_corner = query->Query(Sphere({1.5, 0, 0}, 1), {});
  EXPECT_NEAR(at_corner.material_weight, 3, 1e-12);
  // The middle of face (+x, +y, +z): a third of each corner's weight.
  const Eigen::Vector3d middle = Eigen::Vector3d::Ones() / 3;
  const SkinContact on_face = query->Query(Sphere(middle * 1.5, 0.5), {});
  EXPECT_NEAR(on_face.material_weight, (3 + 1 + 1) / 3.0, 1e-9);
}

TEST(SkinContactQuery, RefusesBadWeightsAndStiffness) {
  EXPECT_FALSE(SkinContactQuery::Create(Octahedron(), std::vector<double>(5, 1.0)).ok());
  std::vector<double> weights(6, 1.0);
  weights[2] = -1;
  const auto refused = SkinContactQuery::Create(Octahedron(), weights);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("vertex 2"), std::string::npos);
  EXPECT_FALSE(ValidateContactForceModel({0}).ok());
  EXPECT_FALSE(ValidateContactForceModel({std::nan("")}).ok());
  EXPECT_TRUE(ValidateContactForceModel({}).ok());
}

// On a closed mesh the sign agrees with the tree's ray-parity inside test for points not at the
// surface, and the distance with the tree's point query.
void ExpectSignsMatchContainment(const TriangleMesh& mesh, int points, unsigned seed) {
  const auto query = SkinContactQuery::Create(mesh, {}).value();
  const TriangleBvh& tree = query->tree();
  const Eigen::Vector3d lower = tree.lower(), upper = tree.upper();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  int inside = 0;
  for (int p = 0; p < points; ++p) {
    const Eigen::Vector3d x =
        lower +
        Eigen::Vector3d(unit(random), unit(random), unit(random)).cwiseProduct(upper - lower);
    const SkinContact contact = query->Query(Sphere(x, 1e-3 * query->rest_diagonal()), {});
    EXPECT_NEAR(std::abs(contact.signed_distance), tree.DistanceToSurface(x),
                1e-9 * query->rest_diagonal());
    if (std::abs(contact.signed_distance) < 1e-6 * query->rest_diagonal()) continue;
    const bool contained = tree.Contains(x);
    inside += contained ? 1 : 0;
    EXPECT_EQ(contact.signed_distance < 0, contained) << "point " << p;
  }
  EXPECT_GT(inside, points / 20);
}

TEST(SkinContactQuery, SignsMatchContainmentOnAGeneratedLimb) {
  ExpectSignsMatchContainment((*MakeKneePhantom(2000)).mesh, 300, 3);
}

TEST(SkinContactQuery, SignsMatchContainmentOnTheSharedArm) {
  DEFORM_REQUIRE_SHARED_FILE(path, "arm/arm_8311.obj");
  ExpectSignsMatchContainment(*ReadMeshFile(path), 300, 5);
}

TEST(SkinContactQuery, RefitAndQueryAllocateNothingAndFollowTheFrame) {
  DEFORM_REQUIRE_SHARED_FILE(path, "leg/leg_1633.obj");
  const TriangleMesh leg = *ReadMeshFile(path);
  auto query = SkinContactQuery::Create(leg, {}).value();
  Positions moved = leg.vertices;
  moved.col(0).array() += 0.1 * query->rest_diagonal();
  const Eigen::Vector3d probe = leg.vertices.row(0).transpose();
  const Tool tool = Sphere(probe, 0.01 * query->rest_diagonal());
  const SkinContact at_rest = query->Query(tool, {});
  EXPECT_NEAR(at_rest.signed_distance, 0, 1e-12);
  EXPECT_NEAR(at_rest.depth, tool.radius, 1e-12);
  const long before = test_support::AllocationCount();
  query->Refit(moved.data());
  const SkinContact moved_contact = query->Query(tool, {});
  EXPECT_EQ(test_support::AllocationCount(), before);
  // The skin moved away along x by a tenth of the diagonal: the vertex is now that far off.
  EXPECT_GT(std::abs(moved_contact.signed_distance), 0.01 * query->rest_diagonal());
  EXPECT_EQ(moved_contact.depth, 0);
}

}  // namespace
}  // namespace deform
