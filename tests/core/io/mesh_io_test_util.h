// The meshes, file bytes and checks shared by the mesh reading and writing tests
// (mesh_io_test.cc and mesh_io_<format>_test.cc).
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/io/mesh_io.h"

namespace deform::mesh_io_test {

// ---------------------------------------------------------------------------------------------
// Meshes and bytes

inline TriangleMesh MakeMesh(const std::vector<std::array<double, 3>>& vertices,
                             const std::vector<std::array<int, 3>>& triangles) {
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      mesh.vertices(static_cast<Eigen::Index>(v), axis) = vertices[v][axis];
    }
  }
  mesh.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) mesh.triangles(static_cast<Eigen::Index>(t), c) = triangles[t][c];
  }
  return mesh;
}

inline const std::vector<std::array<double, 3>> kCubeVertices = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
inline const std::vector<std::array<int, 3>> kCubeTriangles = {
    {0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
    {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

// A closed unit cube: 8 vertices, 12 consistently oriented triangles.
inline TriangleMesh Cube() { return MakeMesh(kCubeVertices, kCubeTriangles); }

// An open (n+1)^2-vertex grid of 2 n^2 triangles in the z = 0 plane.
inline TriangleMesh Grid(int n) {
  TriangleMesh mesh;
  mesh.vertices.resize((n + 1) * (n + 1), 3);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) mesh.vertices.row(i * (n + 1) + j) << i, j, 0.0;
  }
  mesh.triangles.resize(2 * n * n, 3);
  int t = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j;
      const int b = a + 1;
      const int c = a + n + 1;
      const int d = c + 1;
      mesh.triangles.row(t++) << a, b, d;
      mesh.triangles.row(t++) << a, d, c;
    }
  }
  return mesh;
}

// A closed cube with coordinates that are not short decimals (tests precision).
inline TriangleMesh SkewedCube() {
  TriangleMesh mesh = Cube();
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    mesh.vertices.row(v) = mesh.vertices.row(v) * (1.0 / 3.0) +
                           Eigen::RowVector3d(0.1 * static_cast<double>(v), -7.25, 1e-3);
  }
  return mesh;
}

template <typename T>
inline void AppendRaw(std::string* out, T value, bool big_endian = false) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t probe = 1;
  const bool host_little = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  if (big_endian == host_little) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

// A binary STL of `mesh`'s triangles (36 corner records for the cube).
inline std::string BinaryStl(const TriangleMesh& mesh, const std::string& header_text = "test") {
  std::string bytes = header_text;
  bytes.resize(80, ' ');
  AppendRaw(&bytes, static_cast<std::uint32_t>(mesh.num_triangles()));
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    for (int axis = 0; axis < 3; ++axis) AppendRaw(&bytes, 0.0f);
    for (int c = 0; c < 3; ++c) {
      for (int axis = 0; axis < 3; ++axis) {
        AppendRaw(&bytes, static_cast<float>(mesh.vertices(mesh.triangles(t, c), axis)));
      }
    }
    AppendRaw(&bytes, std::uint16_t{0});
  }
  return bytes;
}

inline std::string AsciiStl(const TriangleMesh& mesh) {
  std::string text = "solid cube\n";
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (int c = 0; c < 3; ++c) {
      const auto p = mesh.vertices.row(mesh.triangles(t, c));
      text += "      vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " +
              std::to_string(p[2]) + "\n";
    }
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid cube\n";
}

// "x y z" lines for the vertices, then "3 a b c" lines for the triangles: the body that ASCII PLY
// and OFF share.
inline std::string AsciiVertexAndFaceLines(const TriangleMesh& mesh) {
  std::string text;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    text += std::to_string(mesh.vertices(v, 0)) + " " + std::to_string(mesh.vertices(v, 1)) + " " +
            std::to_string(mesh.vertices(v, 2)) + "\n";
  }
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    text += "3 " + std::to_string(mesh.triangles(t, 0)) + " " +
            std::to_string(mesh.triangles(t, 1)) + " " + std::to_string(mesh.triangles(t, 2)) +
            "\n";
  }
  return text;
}

inline std::string AsciiPly(const TriangleMesh& mesh) {
  std::string text = "ply\nformat ascii 1.0\ncomment a test\nelement vertex " +
                     std::to_string(mesh.num_vertices()) +
                     "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                     std::to_string(mesh.num_triangles()) +
                     "\nproperty list uchar int vertex_indices\nend_header\n";
  return text + AsciiVertexAndFaceLines(mesh);
}

struct BinaryPlyOptions {
  bool big_endian = false;
  std::string count_type = "uchar";     // the list count type
  std::string extra_vertex_properties;  // header lines; each adds one float of value 0.5
};

inline std::string BinaryPly(const TriangleMesh& mesh, const BinaryPlyOptions& options = {}) {
  int extra_floats = 0;
  for (std::size_t pos = 0;
       (pos = options.extra_vertex_properties.find("property", pos)) != std::string::npos; ++pos) {
    ++extra_floats;
  }
  std::string bytes = std::string("ply\nformat ") +
                      (options.big_endian ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\nelement vertex " + std::to_string(mesh.num_vertices()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n" +
                      options.extra_vertex_properties + "element face " +
                      std::to_string(mesh.num_triangles()) + "\nproperty list " +
                      options.count_type + " int vertex_indices\nend_header\n";
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      AppendRaw(&bytes, static_cast<float>(mesh.vertices(v, axis)), options.big_endian);
    }
    for (int i = 0; i < extra_floats; ++i) AppendRaw(&bytes, 0.5f, options.big_endian);
  }
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    if (options.count_type == "uchar") {
      AppendRaw(&bytes, std::uint8_t{3}, options.big_endian);
    } else {
      AppendRaw(&bytes, std::uint32_t{3}, options.big_endian);
    }
    for (int c = 0; c < 3; ++c) AppendRaw(&bytes, mesh.triangles(t, c), options.big_endian);
  }
  return bytes;
}

inline std::string Off(const TriangleMesh& mesh) {
  std::string text = "OFF\n" + std::to_string(mesh.num_vertices()) + " " +
                     std::to_string(mesh.num_triangles()) + " 0\n";
  return text + AsciiVertexAndFaceLines(mesh);
}

inline std::string Obj(const TriangleMesh& mesh) {
  std::string text;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    text += "v " + std::to_string(mesh.vertices(v, 0)) + " " + std::to_string(mesh.vertices(v, 1)) +
            " " + std::to_string(mesh.vertices(v, 2)) + "\n";
  }
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    text += "f " + std::to_string(mesh.triangles(t, 0) + 1) + " " +
            std::to_string(mesh.triangles(t, 1) + 1) + " " +
            std::to_string(mesh.triangles(t, 2) + 1) + "\n";
  }
  return text;
}

// A valid cube in every format and encoding the reader supports.
inline std::vector<std::pair<std::string, MeshFormat>> ValidCubeFiles() {
  return {{Obj(Cube()), MeshFormat::kObj},       {AsciiPly(Cube()), MeshFormat::kPly},
          {BinaryPly(Cube()), MeshFormat::kPly}, {AsciiStl(Cube()), MeshFormat::kStl},
          {BinaryStl(Cube()), MeshFormat::kStl}, {Off(Cube()), MeshFormat::kOff}};
}

inline std::vector<std::array<double, 3>> PositionList(const TriangleMesh& mesh) {
  std::vector<std::array<double, 3>> rows;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    rows.push_back({mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2)});
  }
  return rows;
}

// Positions of `mesh` as a sorted list, to compare meshes whose vertex order may differ (STL).
inline std::vector<std::array<double, 3>> SortedPositions(const TriangleMesh& mesh) {
  std::vector<std::array<double, 3>> rows = PositionList(mesh);
  std::sort(rows.begin(), rows.end());
  return rows;
}

// Expects `mesh` read, with these sizes.
inline void ExpectMeshSize(const StatusOr<TriangleMesh>& mesh, int vertices, int triangles) {
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), vertices);
  EXPECT_EQ(mesh->num_triangles(), triangles);
}

inline void ExpectSamePositionsToFloatPrecision(const std::vector<std::array<double, 3>>& expected,
                                                const std::vector<std::array<double, 3>>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t v = 0; v < expected.size(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      const double tolerance = 1e-6 * std::max(1.0, std::abs(expected[v][axis]));
      EXPECT_NEAR(expected[v][axis], actual[v][axis], tolerance) << "vertex " << v;
    }
  }
}

}  // namespace deform::mesh_io_test

// Expects the Status `status_expr` to have `expected_code` and a message containing `substring`.
#define EXPECT_STATUS(status_expr, expected_code, substring)                               \
  do {                                                                                     \
    const ::deform::Status status_ = (status_expr);                                        \
    EXPECT_EQ(status_.code(), (expected_code)) << status_.ToString();                      \
    EXPECT_THAT(status_.message(), ::testing::HasSubstr(substring)) << status_.ToString(); \
  } while (0)

namespace deform::mesh_io_test {

// Malformed input and what its refusal says: reading `bytes` fails with `code` and a message that
// contains `message`. `what` names the case in failures (and says what it once did to OpenMesh).
struct Refusal {
  std::string what;
  std::string bytes;
  std::string message;
  StatusCode code = StatusCode::kInvalidArgument;
};

// Reads each refusal's bytes as `format` and checks that it is refused as it says.
inline void ExpectRefusals(MeshFormat format, const std::vector<Refusal>& refusals) {
  for (const Refusal& refusal : refusals) {
    SCOPED_TRACE(refusal.what);
    EXPECT_STATUS(ReadMesh(refusal.bytes, format).status(), refusal.code, refusal.message);
  }
}

}  // namespace deform::mesh_io_test
