#include "core/geometry/volume_closure.h"

#include <Eigen/Geometry>
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "core/base/cpu_features.h"

namespace deform {
namespace {

using Vec = Eigen::Map<const Eigen::Vector3d>;

int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

std::int64_t EdgeKey(int a, int b) {
  return (static_cast<std::int64_t>(a) << 32) | static_cast<unsigned>(b);
}

}  // namespace

VolumeClosure::VolumeClosure(const Triangles& triangles, int num_vertices)
    : num_vertices_(num_vertices), triangles_(triangles) {
  // Directed edges: an edge seen once (its reverse absent) lies on the boundary.
  std::unordered_set<std::int64_t> directed;
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c)
      directed.insert(EdgeKey(triangles(f, c), triangles(f, (c + 1) % 3)));
  }
  std::vector<std::pair<int, int>> boundary;
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(f, c), b = triangles(f, (c + 1) % 3);
      if (directed.count(EdgeKey(b, a)) == 0) boundary.emplace_back(a, b);
    }
  }
  if (boundary.empty()) return;
  // Group the boundary edges into loops (connected by their ends).
  std::vector<int> parent(num_vertices);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [a, b] : boundary) parent[FindRoot(parent, a)] = FindRoot(parent, b);
  std::unordered_map<int, std::vector<std::pair<int, int>>> by_root;
  std::vector<int> roots;
  for (const auto& edge : boundary) {
    const int root = FindRoot(parent, edge.first);
    auto [it, inserted] = by_root.try_emplace(root);
    if (inserted) roots.push_back(root);
    it->second.push_back(edge);
  }
  for (int root : roots) {
    Loop loop{static_cast<int>(boundary_.size() / 2), static_cast<int>(by_root[root].size())};
    for (const auto& [a, b] : by_root[root]) {
      boundary_.push_back(a);
      boundary_.push_back(b);
    }
    loops_.push_back(loop);
  }
}

void VolumeClosure::Centroid(const double* xyz, const Loop& loop, double* c) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int e = loop.first_edge; e < loop.first_edge + loop.edges; ++e) {
    sum += Vec(xyz + 3 * boundary_[2 * e]) + Vec(xyz + 3 * boundary_[2 * e + 1]);
  }
  Eigen::Map<Eigen::Vector3d> centroid(c);
  centroid = sum / (2.0 * loop.edges);
}

TriangleMesh VolumeClosure::ClosedMesh(const Positions& positions) const {
  TriangleMesh closed;
  closed.vertices.resize(num_vertices_ + static_cast<Eigen::Index>(loops_.size()), 3);
  closed.vertices.topRows(num_vertices_) = positions.topRows(num_vertices_);
  closed.triangles.resize(triangles_.rows() + static_cast<Eigen::Index>(boundary_.size() / 2), 3);
  closed.triangles.topRows(triangles_.rows()) = triangles_;
  Eigen::Index row = triangles_.rows();
  for (std::size_t l = 0; l < loops_.size(); ++l) {
    const int centre = num_vertices_ + static_cast<int>(l);
    double centroid[3];
    Centroid(positions.data(), loops_[l], centroid);
    closed.vertices.row(centre) << centroid[0], centroid[1], centroid[2];
    for (int e = loops_[l].first_edge; e < loops_[l].first_edge + loops_[l].edges; ++e) {
      closed.triangles.row(row++) << centre, boundary_[2 * e + 1], boundary_[2 * e];
    }
  }
  return closed;
}

double VolumeClosure::Volume(const double* xyz) const {
  double six_volume = 0;
  for (int f = 0; f < triangles_.rows(); ++f) {
    six_volume += Vec(xyz + 3 * triangles_(f, 0))
                      .dot(Vec(xyz + 3 * triangles_(f, 1)).cross(Vec(xyz + 3 * triangles_(f, 2))));
  }
  for (const Loop& loop : loops_) {
    double centroid[3];
    Centroid(xyz, loop, centroid);
    for (int e = loop.first_edge; e < loop.first_edge + loop.edges; ++e) {
      // The fan triangle (centroid, b, a) closes edge (a, b).
      six_volume += Vec(centroid).dot(
          Vec(xyz + 3 * boundary_[2 * e + 1]).cross(Vec(xyz + 3 * boundary_[2 * e])));
    }
  }
  return six_volume / 6.0;
}

namespace {

// Adds the cubic of a . (b x c) with a = a0 + t a1 and so on to c (six times the volume's).
void AddTripleCubic(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                    const Eigen::Vector3d& b1, const Eigen::Vector3d& c0, const Eigen::Vector3d& c1,
                    double* c) {
  const Eigen::Vector3d b0c0 = b0.cross(c0), b1c0 = b1.cross(c0), b0c1 = b0.cross(c1),
                        b1c1 = b1.cross(c1);
  c[0] += a0.dot(b0c0);
  c[1] += a1.dot(b0c0) + a0.dot(b1c0 + b0c1);
  c[2] += a1.dot(b1c0 + b0c1) + a0.dot(b1c1);
  c[3] += a1.dot(b1c1);
}

}  // namespace

namespace {

// The mesh triangles' share of VolumeAlong (times 6): plain arithmetic, written for the compiler
// to keep in registers, since this pass runs every frame that keeps the volume.
inline void TriangleCubic(const int* t, int faces, const double* xyz, const double* direction,
                          double c[4]) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  for (int f = 0; f < faces; ++f) {
    const double* a0 = xyz + 3 * t[3 * f];
    const double* b0 = xyz + 3 * t[3 * f + 1];
    const double* c0 = xyz + 3 * t[3 * f + 2];
    const double* a1 = direction + 3 * t[3 * f];
    const double* b1 = direction + 3 * t[3 * f + 1];
    const double* c1 = direction + 3 * t[3 * f + 2];
    auto cross = [](const double* u, const double* v, double* w) {
      w[0] = u[1] * v[2] - u[2] * v[1];
      w[1] = u[2] * v[0] - u[0] * v[2];
      w[2] = u[0] * v[1] - u[1] * v[0];
    };
    double bc[3], Bc[3], bC[3], BC[3];
    cross(b0, c0, bc);
    cross(b1, c0, Bc);
    cross(b0, c1, bC);
    cross(b1, c1, BC);
    const double mixed[3] = {Bc[0] + bC[0], Bc[1] + bC[1], Bc[2] + bC[2]};
    s0 += a0[0] * bc[0] + a0[1] * bc[1] + a0[2] * bc[2];
    s1 += a1[0] * bc[0] + a1[1] * bc[1] + a1[2] * bc[2] + a0[0] * mixed[0] + a0[1] * mixed[1] +
          a0[2] * mixed[2];
    s2 += a1[0] * mixed[0] + a1[1] * mixed[1] + a1[2] * mixed[2] + a0[0] * BC[0] + a0[1] * BC[1] +
          a0[2] * BC[2];
    s3 += a1[0] * BC[0] + a1[1] * BC[1] + a1[2] * BC[2];
  }
  c[0] = s0;
  c[1] = s1;
  c[2] = s2;
  c[3] = s3;
}

#if defined(__x86_64__) && defined(__GNUC__)
// Coordinates x, y, z of four points (row p[j] of a rows-by-3 array, j < 4), one register each,
// lane j: four masked loads (the fourth double is never read: the last row may end the array) and
// a 4x4 transpose.
__attribute__((target("avx2,fma"))) inline void LoadFour(const double* p0, const double* p1,
                                                         const double* p2, const double* p3,
                                                         __m256d xyz[3]) {
  const __m256i first_three = _mm256_setr_epi64x(-1, -1, -1, 0);
  const __m256d r0 = _mm256_maskload_pd(p0, first_three);
  const __m256d r1 = _mm256_maskload_pd(p1, first_three);
  const __m256d r2 = _mm256_maskload_pd(p2, first_three);
  const __m256d r3 = _mm256_maskload_pd(p3, first_three);
  const __m256d lo01 = _mm256_unpacklo_pd(r0, r1);  // x0 x1 z0 z1
  const __m256d hi01 = _mm256_unpackhi_pd(r0, r1);  // y0 y1 .  .
  const __m256d lo23 = _mm256_unpacklo_pd(r2, r3);  // x2 x3 z2 z3
  const __m256d hi23 = _mm256_unpackhi_pd(r2, r3);  // y2 y3 .  .
  xyz[0] = _mm256_permute2f128_pd(lo01, lo23, 0x20);
  xyz[1] = _mm256_permute2f128_pd(hi01, hi23, 0x20);
  xyz[2] = _mm256_permute2f128_pd(lo01, lo23, 0x31);
}

__attribute__((target("avx2,fma"))) inline void Cross4(const __m256d u[3], const __m256d v[3],
                                                       __m256d w[3]) {
  w[0] = _mm256_fmsub_pd(u[1], v[2], _mm256_mul_pd(u[2], v[1]));
  w[1] = _mm256_fmsub_pd(u[2], v[0], _mm256_mul_pd(u[0], v[2]));
  w[2] = _mm256_fmsub_pd(u[0], v[1], _mm256_mul_pd(u[1], v[0]));
}

__attribute__((target("avx2,fma"))) inline __m256d Dot4(const __m256d u[3], const __m256d v[3],
                                                        __m256d sum) {
  sum = _mm256_fmadd_pd(u[0], v[0], sum);
  sum = _mm256_fmadd_pd(u[1], v[1], sum);
  return _mm256_fmadd_pd(u[2], v[2], sum);
}

// TriangleCubic on four triangles a step, one a lane, with fused multiply-adds (the rest, fewer
// than four, as TriangleCubic): the scalar pass is bound by its arithmetic, and this pass runs
// every frame that keeps the volume.
__attribute__((target("avx2,fma"))) void TriangleCubicFma(const int* t, int faces,
                                                          const double* xyz,
                                                          const double* direction, double c[4]) {
  __m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
  int f = 0;
  for (; f + 4 <= faces; f += 4) {
    const int* q = t + 3 * f;
    __m256d a0[3], b0[3], c0[3], a1[3], b1[3], c1[3];
    LoadFour(xyz + 3 * q[0], xyz + 3 * q[3], xyz + 3 * q[6], xyz + 3 * q[9], a0);
    LoadFour(xyz + 3 * q[1], xyz + 3 * q[4], xyz + 3 * q[7], xyz + 3 * q[10], b0);
    LoadFour(xyz + 3 * q[2], xyz + 3 * q[5], xyz + 3 * q[8], xyz + 3 * q[11], c0);
    LoadFour(direction + 3 * q[0], direction + 3 * q[3], direction + 3 * q[6], direction + 3 * q[9],
             a1);
    LoadFour(direction + 3 * q[1], direction + 3 * q[4], direction + 3 * q[7],
             direction + 3 * q[10], b1);
    LoadFour(direction + 3 * q[2], direction + 3 * q[5], direction + 3 * q[8],
             direction + 3 * q[11], c1);
    __m256d bc[3], Bc[3], bC[3], BC[3];
    Cross4(b0, c0, bc);
    Cross4(b1, c0, Bc);
    Cross4(b0, c1, bC);
    Cross4(b1, c1, BC);
    const __m256d mixed[3] = {_mm256_add_pd(Bc[0], bC[0]), _mm256_add_pd(Bc[1], bC[1]),
                              _mm256_add_pd(Bc[2], bC[2])};
    s0 = Dot4(a0, bc, s0);
    s1 = Dot4(a0, mixed, Dot4(a1, bc, s1));
    s2 = Dot4(a0, BC, Dot4(a1, mixed, s2));
    s3 = Dot4(a1, BC, s3);
  }
  alignas(32) double lanes[4][4];
  _mm256_store_pd(lanes[0], s0);
  _mm256_store_pd(lanes[1], s1);
  _mm256_store_pd(lanes[2], s2);
  _mm256_store_pd(lanes[3], s3);
  double rest[4];
  TriangleCubic(t + 3 * f, faces - f, xyz, direction, rest);
  for (int p = 0; p < 4; ++p) {
    c[p] = ((lanes[p][0] + lanes[p][1]) + (lanes[p][2] + lanes[p][3])) + rest[p];
  }
}
#endif

}  // namespace

void VolumeClosure::VolumeAlong(const double* xyz, const double* direction, double c[4]) const {
  const int* t = triangles_.data();
  const int faces = static_cast<int>(triangles_.rows());
#if defined(__x86_64__) && defined(__GNUC__)
  if (CpuHasAvx2Fma()) {
    TriangleCubicFma(t, faces, xyz, direction, c);
  } else {
    TriangleCubic(t, faces, xyz, direction, c);
  }
#else
  TriangleCubic(t, faces, xyz, direction, c);
#endif
  for (const Loop& loop : loops_) {
    double centroid[3], moved[3];
    Centroid(xyz, loop, centroid);
    Centroid(direction, loop, moved);
    for (int e = loop.first_edge; e < loop.first_edge + loop.edges; ++e) {
      const int a = boundary_[2 * e], b = boundary_[2 * e + 1];
      AddTripleCubic(Vec(centroid), Vec(moved), Vec(xyz + 3 * b), Vec(direction + 3 * b),
                     Vec(xyz + 3 * a), Vec(direction + 3 * a), c);
    }
  }
  for (int p = 0; p < 4; ++p) c[p] /= 6.0;
}

void VolumeClosure::Gradient(const double* xyz, double* gradient) const {
  Eigen::Map<Eigen::VectorXd>(gradient, 3 * num_vertices_).setZero();
  auto g = [&](int i) { return Eigen::Map<Eigen::Vector3d>(gradient + 3 * i); };
  for (int f = 0; f < triangles_.rows(); ++f) {
    const int a = triangles_(f, 0), b = triangles_(f, 1), c = triangles_(f, 2);
    const Vec pa(xyz + 3 * a), pb(xyz + 3 * b), pc(xyz + 3 * c);
    g(a) += pb.cross(pc) / 6.0;
    g(b) += pc.cross(pa) / 6.0;
    g(c) += pa.cross(pb) / 6.0;
  }
  for (const Loop& loop : loops_) {
    double centroid_data[3];
    Centroid(xyz, loop, centroid_data);
    const Vec centroid(centroid_data);
    // d/d(centroid) of the loop's fan, spread over the edges' ends that make the centroid.
    Eigen::Vector3d d_centroid = Eigen::Vector3d::Zero();
    for (int e = loop.first_edge; e < loop.first_edge + loop.edges; ++e) {
      const int a = boundary_[2 * e], b = boundary_[2 * e + 1];
      const Vec pa(xyz + 3 * a), pb(xyz + 3 * b);
      // Triangle (centroid, b, a): d/db = a x centroid, d/da = centroid x b, d/dc = b x a.
      g(b) += pa.cross(centroid) / 6.0;
      g(a) += centroid.cross(pb) / 6.0;
      d_centroid += pb.cross(pa) / 6.0;
    }
    const Eigen::Vector3d share = d_centroid / (2.0 * loop.edges);
    for (int e = loop.first_edge; e < loop.first_edge + loop.edges; ++e) {
      g(boundary_[2 * e]) += share;
      g(boundary_[2 * e + 1]) += share;
    }
  }
}

}  // namespace deform
