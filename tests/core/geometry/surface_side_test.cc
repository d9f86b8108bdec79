#include "core/geometry/surface_side.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "core/geometry/primitive_surfaces.h"
#include "core/io/phantom.h"

namespace deform {
namespace {

// Two surfaces in one mesh: `b`'s vertices after `a`'s.
TriangleMesh Union(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out;
  out.vertices.resize(a.vertices.rows() + b.vertices.rows(), 3);
  out.vertices << a.vertices, b.vertices;
  out.triangles.resize(a.triangles.rows() + b.triangles.rows(), 3);
  out.triangles << a.triangles,
      (b.triangles.array() + static_cast<int>(a.vertices.rows())).matrix();
  return out;
}

// Points in the surface's box grown by a fifth, half of them within a tenth of the diagonal of
// the surface (where the nearest feature is an edge or a corner as often as a face): the side
// the pseudo-normals give agrees with the rays' parity wherever both are sure.
int CountDisagreements(const TriangleMesh& mesh, int points, int* unsure) {
  const TriangleBvh bvh(mesh);
  const auto side = SurfaceSide::Make(bvh);
  EXPECT_NE(side, nullptr);
  if (side == nullptr) return -1;
  const Eigen::Vector3d lower = bvh.lower(), upper = bvh.upper();
  const double diagonal = (upper - lower).norm();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  int disagreements = 0;
  *unsure = 0;
  for (int i = 0; i < points; ++i) {
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      p[a] = lower[a] - 0.2 * (upper[a] - lower[a]) + 1.4 * (upper[a] - lower[a]) * unit(random);
    }
    if (i % 2 == 1) {  // near the surface: off a random vertex along a random direction
      const int v = static_cast<int>(unit(random) * (mesh.num_vertices() - 1));
      const Eigen::Vector3d d =
          Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5).normalized();
      p = mesh.vertices.row(v).transpose() + 0.1 * diagonal * unit(random) * d;
    }
    const TriangleBvh::SurfacePoint nearest = bvh.ClosestPoint(p);
    const SurfaceSide::Side found = side->Of(p, nearest);
    if (found == SurfaceSide::Side::kUnsure) {
      ++*unsure;
      continue;
    }
    if ((found == SurfaceSide::Side::kInside) != bvh.Contains(p)) ++disagreements;
  }
  return disagreements;
}

TEST(SurfaceSide, AgreesWithTheRaysOnClosedSurfaces) {
  int unsure = 0;
  EXPECT_EQ(CountDisagreements(MakeCapsule({0, 0, 0}, {0, 0, 3}, 0.7, 12, 3), 20000, &unsure), 0);
  EXPECT_LE(unsure, 2);
  Eigen::Matrix3d axes = Eigen::Vector3d(1.0, 0.4, 2.5).asDiagonal();
  axes = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() * axes;
  EXPECT_EQ(CountDisagreements(MakeEllipsoid({1, 2, 3}, axes, 10, 6), 20000, &unsure), 0);
  EXPECT_LE(unsure, 2);
  // Two pieces apart.
  EXPECT_EQ(CountDisagreements(Union(MakeCapsule({0, 0, 0}, {0, 0, 1}, 0.3),
                                     MakeCapsule({2, 0, 0}, {2, 1, 1}, 0.4)),
                               20000, &unsure),
            0);
  // The phantom's femur, tibia and patella.
  const KneePhantom phantom = *MakeKneePhantom(800);
  ASSERT_FALSE(phantom.bones.empty());
  for (const BoneSurface& bone : phantom.bones) {
    EXPECT_EQ(CountDisagreements(bone.mesh, 20000, &unsure), 0) << bone.name;
    EXPECT_LE(unsure, 2) << bone.name;
  }
}

TEST(SurfaceSide, RefusesSurfacesItCannotAnswerFor) {
  TriangleMesh capsule = MakeCapsule({0, 0, 0}, {0, 0, 2}, 0.5);
  ASSERT_NE(SurfaceSide::Make(TriangleBvh(capsule)), nullptr);
  // A hole.
  TriangleMesh open = capsule;
  open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
  EXPECT_EQ(SurfaceSide::Make(TriangleBvh(open)), nullptr);
  // Inward normals.
  TriangleMesh inward = capsule;
  inward.triangles.col(1).swap(inward.triangles.col(2));
  EXPECT_EQ(SurfaceSide::Make(TriangleBvh(inward)), nullptr);
  // One triangle turned the other way: the orientation is not consistent.
  TriangleMesh flipped = capsule;
  std::swap(flipped.triangles(0, 1), flipped.triangles(0, 2));
  EXPECT_EQ(SurfaceSide::Make(TriangleBvh(flipped)), nullptr);
  // Two surfaces passing through each other.
  EXPECT_EQ(
      SurfaceSide::Make(TriangleBvh(Union(capsule, MakeCapsule({0.3, 0, 1}, {0.3, 0, 3}, 0.5)))),
      nullptr);
  // Two surfaces touching at one shared vertex (two cones at a corner): the capsule and its
  // mirror image below its lowest vertex, which they share.
  int low = 0;
  capsule.vertices.col(2).minCoeff(&low);
  TriangleMesh touching = Union(capsule, capsule);
  const int shift = static_cast<int>(capsule.vertices.rows());
  const int faces = static_cast<int>(capsule.triangles.rows());
  for (int v = shift; v < touching.vertices.rows(); ++v) {
    touching.vertices(v, 2) = 2 * capsule.vertices(low, 2) - touching.vertices(v, 2);
  }
  for (int f = faces; f < 2 * faces; ++f) {
    std::swap(touching.triangles(f, 1), touching.triangles(f, 2));  // outward again
    for (int c = 0; c < 3; ++c) {
      if (touching.triangles(f, c) == shift + low) touching.triangles(f, c) = low;
    }
  }
  EXPECT_EQ(SurfaceSide::Make(TriangleBvh(touching)), nullptr);
  // The same two apart (the mirror image shifted down, no vertex shared) are answered.
  TriangleMesh apart = Union(capsule, capsule);
  for (int v = shift; v < apart.vertices.rows(); ++v) {
    apart.vertices(v, 2) = 2 * capsule.vertices(low, 2) - apart.vertices(v, 2) - 0.5;
  }
  for (int f = faces; f < 2 * faces; ++f) std::swap(apart.triangles(f, 1), apart.triangles(f, 2));
  EXPECT_NE(SurfaceSide::Make(TriangleBvh(apart)), nullptr);
  // A triangle without area.
  TriangleMesh flat = capsule;
  flat.vertices.row(flat.triangles(0, 1)) = flat.vertices.row(flat.triangles(0, 0));
  EXPECT_EQ(SurfaceSide::Make(TriangleBvh(flat)), nullptr);
}

}  // namespace
}  // namespace deform
