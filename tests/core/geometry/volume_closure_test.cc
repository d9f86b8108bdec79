#include "core/geometry/volume_closure.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/geometry/enclosed_volume.h"
#include "core/geometry/primitive_surfaces.h"
#include "core/io/phantom.h"

namespace deform {
namespace {

// A capsule without its top fan: an open mesh, closed by the fan of its boundary loop.
TriangleMesh OpenCapsule() {
  TriangleMesh mesh = MakeCapsule(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1), 0.4, 12, 3);
  const int fan = 12;
  mesh.triangles = mesh.triangles.bottomRows(mesh.num_triangles() - fan).eval();
  return mesh;
}

TEST(VolumeClosure, MatchesEnclosedVolumeOnClosedAndOpenMeshes) {
  for (const TriangleMesh& mesh : {MakeKneePhantom(800)->mesh, OpenCapsule()}) {
    const VolumeClosure closure(mesh.triangles, mesh.num_vertices());
    EXPECT_DOUBLE_EQ(closure.Volume(mesh.vertices.data()),
                     EnclosedVolume(mesh.vertices, mesh.triangles));
  }
  EXPECT_FALSE(VolumeClosure(OpenCapsule().triangles, OpenCapsule().num_vertices()).closed());
}

TEST(VolumeClosure, TheVolumeAlongALineIsItsCubic) {
  const TriangleMesh mesh = OpenCapsule();
  const VolumeClosure closure(mesh.triangles, mesh.num_vertices());
  Positions direction = Positions::Random(mesh.num_vertices(), 3);
  double c[4];
  closure.VolumeAlong(mesh.vertices.data(), direction.data(), c);
  for (double t : {-0.7, 0.0, 0.3, 1.9}) {
    const Positions moved = mesh.vertices + t * direction;
    EXPECT_NEAR(c[0] + t * (c[1] + t * (c[2] + t * c[3])), closure.Volume(moved.data()), 1e-12);
  }
}

TEST(VolumeClosure, GradientMatchesFiniteDifferences) {
  TriangleMesh mesh = OpenCapsule();
  const VolumeClosure closure(mesh.triangles, mesh.num_vertices());
  std::vector<double> gradient(3 * mesh.num_vertices());
  closure.Gradient(mesh.vertices.data(), gradient.data());
  const double h = 1e-6;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double kept = mesh.vertices(i, c);
      mesh.vertices(i, c) = kept + h;
      const double up = closure.Volume(mesh.vertices.data());
      mesh.vertices(i, c) = kept - h;
      const double down = closure.Volume(mesh.vertices.data());
      mesh.vertices(i, c) = kept;
      EXPECT_NEAR(gradient[3 * i + c], (up - down) / (2 * h), 1e-8) << i << " " << c;
    }
  }
}

}  // namespace
}  // namespace deform
