#include "core/io/phantom.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/geometry/primitive_surfaces.h"

namespace deform {
namespace {

constexpr double kHipY = 8.0;
constexpr double kKneeY = 3.8;
constexpr double kAnkleY = 0.0;
constexpr double kTopY = 8.3;       // the rounded top cap ends here
constexpr double kBottomY = -0.35;  // the rounded bottom cap ends here
constexpr double kCapLength = 0.35;

double Smooth(double a, double b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  const double s = t * t * (3 - 2 * t);
  return a + (b - a) * s;
}

// Mean radius of the leg's cross-section at height y (thigh 0.85 at the hip, knee 0.52, calf
// bulge 0.58, ankle 0.32), rounded off into caps at both ends.
double ProfileRadius(double y) {
  double r;
  if (y >= kKneeY) {
    r = Smooth(0.52, 0.85, (y - kKneeY) / (kHipY - kKneeY));
  } else if (y >= 2.7) {
    r = Smooth(0.58, 0.52, (y - 2.7) / (kKneeY - 2.7));
  } else {
    r = Smooth(0.32, 0.58, (y - 0.4) / (2.7 - 0.4));
  }
  const double top = (y - (kTopY - kCapLength)) / kCapLength;
  const double bottom = ((kBottomY + kCapLength) - y) / kCapLength;
  if (top > 0) r *= std::sqrt(std::max(0.0, 1 - top * top));
  if (bottom > 0) r *= std::sqrt(std::max(0.0, 1 - bottom * bottom));
  return r;
}

// Radius in direction theta (0 = front, +Z): slightly wider side to side, with a kneecap bump.
double SurfaceRadius(double y, double theta) {
  const double base = ProfileRadius(y) * (1 + 0.06 * std::cos(2 * theta + M_PI));
  const double front = std::max(0.0, std::cos(theta));
  const double kneecap =
      0.10 * std::exp(-std::pow((y - (kKneeY + 0.1)) / 0.3, 2)) * std::pow(front, 4);
  return base + kneecap;
}

StatusOr<Skeleton> PhantomSkeleton() {
  std::vector<Joint> joints(3);
  joints[0].name = "hip";
  joints[0].rest_position = {0, kHipY, 0};
  joints[0].dofs = {{"flexion", {-1, 0, 0}, -20, 120},
                    {"abduction", {0, 0, -1}, -30, 45},
                    {"rotation", {0, 1, 0}, -40, 40}};
  joints[1].name = "knee";
  joints[1].rest_position = {0, kKneeY, 0};
  joints[1].dofs = {{"flexion", {1, 0, 0}, -5, 150},
                    {"varus_valgus", {0, 0, 1}, -15, 15},
                    {"rotation", {0, 1, 0}, -30, 30}};
  joints[2].name = "ankle";
  joints[2].rest_position = {0, kAnkleY, 0};
  return Skeleton::Create(std::move(joints), {{0, 1}, {1, 2}});
}

// Rings of `segments` vertices along y between the two poles: the top pole (vertex 0), ring r's
// vertex s at 1 + r * segments + s, the bottom pole last.
Positions PhantomVertices(int rings, int segments) {
  Positions vertices(static_cast<Eigen::Index>(rings) * segments + 2, 3);
  int v = 0;
  vertices.row(v++) << 0, kTopY, 0;
  for (int ring = 0; ring < rings; ++ring) {
    const double y = kTopY - (kTopY - kBottomY) * (ring + 1.0) / (rings + 1.0);
    for (int s = 0; s < segments; ++s) {
      const double theta = 2 * M_PI * s / segments;
      const double r = SurfaceRadius(y, theta);
      vertices.row(v++) << r * std::sin(theta), y, r * std::cos(theta);
    }
  }
  vertices.row(v) << 0, kBottomY, 0;
  return vertices;
}

// Outward-facing triangles (counter-clockwise seen from outside) over PhantomVertices' layout.
Triangles PhantomTriangles(int rings, int segments) {
  const int bottom_pole = rings * segments + 1;
  const auto ring_vertex = [segments](int ring, int s) {
    return 1 + ring * segments + (s % segments);
  };
  Triangles triangles(2 * segments * rings, 3);
  int f = 0;
  for (int s = 0; s < segments; ++s) {
    triangles.row(f++) << 0, ring_vertex(0, s), ring_vertex(0, s + 1);
  }
  for (int ring = 0; ring + 1 < rings; ++ring) {
    for (int s = 0; s < segments; ++s) {
      const int a = ring_vertex(ring, s), b = ring_vertex(ring, s + 1);
      const int c = ring_vertex(ring + 1, s), d = ring_vertex(ring + 1, s + 1);
      triangles.row(f++) << a, d, b;
      triangles.row(f++) << a, c, d;
    }
  }
  for (int s = 0; s < segments; ++s) {
    triangles.row(f++) << bottom_pole, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s);
  }
  triangles.conservativeResize(f, 3);
  return triangles;
}

// The femur and the tibia as capsules by MakeCapsuleBoneSurfaces' sizing rule, and a patella in
// front of the knee: an ellipsoid (0.15 wide, 0.17 high, 0.07 thick) centred 0.32 in front of the
// knee centre, 0.1 above it (the kneecap bump of the skin), turning by half the knee's rotation
// about its centre, as the patella tracks the femoral groove while the tibia rolls.
std::vector<BoneSurface> PhantomBones(const TriangleMesh& skin, const Skeleton& skeleton) {
  std::vector<BoneSurface> bones = MakeCapsuleBoneSurfaces(skin, skeleton);
  for (BoneSurface& bone : bones) bone.name = bone.bone == 0 ? "femur" : "tibia";
  BoneSurface patella;
  patella.name = "patella";
  patella.bone = 0;
  patella.blend_bone = 1;
  patella.blend = 0.5;
  patella.mesh = MakeEllipsoid(Eigen::Vector3d(0, kKneeY + 0.1, 0.32),
                               Eigen::Vector3d(0.15, 0.17, 0.07).asDiagonal(), 16, 8);
  bones.push_back(std::move(patella));
  return bones;
}

}  // namespace

StatusOr<KneePhantom> MakeKneePhantom(int target_vertices) {
  if (target_vertices < 200 || target_vertices > kMaxPhantomVertices) {
    return Status::InvalidArgument("phantom resolution must be in [200, " +
                                   std::to_string(kMaxPhantomVertices) + "] vertices, got " +
                                   std::to_string(target_vertices));
  }
  // Rings of `segments` vertices along y, spaced about as far apart as the vertices of a ring.
  constexpr double kAspect = 2.4;  // length / circumference of the leg, roughly
  const int segments =
      std::max(8, static_cast<int>(std::lround(std::sqrt(target_vertices / kAspect))));
  const int rings = std::max(4, (target_vertices - 2) / segments);
  KneePhantom phantom;
  phantom.mesh.vertices = PhantomVertices(rings, segments);
  phantom.mesh.triangles = PhantomTriangles(rings, segments);
  DEFORM_ASSIGN_OR_RETURN(phantom.skeleton, PhantomSkeleton());
  phantom.bones = PhantomBones(phantom.mesh, phantom.skeleton);
  return phantom;
}

}  // namespace deform
