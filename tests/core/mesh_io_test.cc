// Tests of mesh validation (core/mesh.h) and mesh reading and writing (core/mesh_io.h).
//
// Malformed inputs are written as bytes in the tests themselves. Many of them used to hang,
// abort or crash OpenMesh's readers before the checks in mesh_io.cc; each is noted below.
#include "core/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/mesh.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

using ::testing::HasSubstr;

// ---------------------------------------------------------------------------------------------
// Meshes and bytes

TriangleMesh MakeMesh(const std::vector<std::array<double, 3>>& vertices,
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

const std::vector<std::array<double, 3>> kCubeVertices = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const std::vector<std::array<int, 3>> kCubeTriangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7},
                                                        {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
                                                        {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

// A closed unit cube: 8 vertices, 12 consistently oriented triangles.
TriangleMesh Cube() { return MakeMesh(kCubeVertices, kCubeTriangles); }

// An open (n+1)^2-vertex grid of 2 n^2 triangles in the z = 0 plane.
TriangleMesh Grid(int n) {
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
TriangleMesh SkewedCube() {
  TriangleMesh mesh = Cube();
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    mesh.vertices.row(v) = mesh.vertices.row(v) * (1.0 / 3.0) +
                           Eigen::RowVector3d(0.1 * static_cast<double>(v), -7.25, 1e-3);
  }
  return mesh;
}

template <typename T>
void AppendRaw(std::string* out, T value, bool big_endian = false) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t probe = 1;
  const bool host_little = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  if (big_endian == host_little) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

// A binary STL of `mesh`'s triangles (36 corner records for the cube).
std::string BinaryStl(const TriangleMesh& mesh, const std::string& header_text = "test") {
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

std::string AsciiStl(const TriangleMesh& mesh) {
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

std::string AsciiPly(const TriangleMesh& mesh) {
  std::string text = "ply\nformat ascii 1.0\ncomment a test\nelement vertex " +
                     std::to_string(mesh.num_vertices()) +
                     "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                     std::to_string(mesh.num_triangles()) +
                     "\nproperty list uchar int vertex_indices\nend_header\n";
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

struct BinaryPlyOptions {
  bool big_endian = false;
  std::string count_type = "uchar";     // the list count type
  std::string extra_vertex_properties;  // header lines; each adds one float of value 0.5
};

std::string BinaryPly(const TriangleMesh& mesh, const BinaryPlyOptions& options = {}) {
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

std::string Off(const TriangleMesh& mesh) {
  std::string text = "OFF\n" + std::to_string(mesh.num_vertices()) + " " +
                     std::to_string(mesh.num_triangles()) + " 0\n";
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

std::string Obj(const TriangleMesh& mesh) {
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
std::vector<std::pair<std::string, MeshFormat>> ValidCubeFiles() {
  return {{Obj(Cube()), MeshFormat::kObj},       {AsciiPly(Cube()), MeshFormat::kPly},
          {BinaryPly(Cube()), MeshFormat::kPly}, {AsciiStl(Cube()), MeshFormat::kStl},
          {BinaryStl(Cube()), MeshFormat::kStl}, {Off(Cube()), MeshFormat::kOff}};
}

std::vector<std::array<double, 3>> PositionList(const TriangleMesh& mesh) {
  std::vector<std::array<double, 3>> rows;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    rows.push_back({mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2)});
  }
  return rows;
}

// Positions of `mesh` as a sorted list, to compare meshes whose vertex order may differ (STL).
std::vector<std::array<double, 3>> SortedPositions(const TriangleMesh& mesh) {
  std::vector<std::array<double, 3>> rows = PositionList(mesh);
  std::sort(rows.begin(), rows.end());
  return rows;
}

void ExpectSamePositionsToFloatPrecision(const std::vector<std::array<double, 3>>& expected,
                                         const std::vector<std::array<double, 3>>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t v = 0; v < expected.size(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      const double tolerance = 1e-6 * std::max(1.0, std::abs(expected[v][axis]));
      EXPECT_NEAR(expected[v][axis], actual[v][axis], tolerance) << "vertex " << v;
    }
  }
}

#define EXPECT_STATUS(status_expr, expected_code, substring)                               \
  do {                                                                                     \
    const ::deform::Status status_ = (status_expr);                                        \
    EXPECT_EQ(status_.code(), (expected_code)) << status_.ToString();                      \
    EXPECT_THAT(status_.message(), ::testing::HasSubstr(substring)) << status_.ToString(); \
  } while (0)

// ---------------------------------------------------------------------------------------------
// ValidateMesh and BoundingBoxDiagonal

TEST(ValidateMeshTest, AcceptsClosedCube) { EXPECT_TRUE(ValidateMesh(Cube()).ok()); }

TEST(ValidateMeshTest, AcceptsOpenMeshWithBoundary) {
  EXPECT_TRUE(ValidateMesh(Grid(3)).ok());
  EXPECT_TRUE(ValidateMesh(MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}})).ok());
}

TEST(ValidateMeshTest, RejectsMeshWithoutVertices) {
  EXPECT_STATUS(ValidateMesh(TriangleMesh{}), StatusCode::kInvalidArgument, "no vertices");
}

TEST(ValidateMeshTest, RejectsMeshWithoutTriangles) {
  EXPECT_STATUS(ValidateMesh(MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {})),
                StatusCode::kInvalidArgument, "no triangles");
}

TEST(ValidateMeshTest, RejectsNaNCoordinateNamingTheVertex) {
  TriangleMesh mesh = Cube();
  mesh.vertices(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "vertex 5 has a non-finite coordinate");
}

TEST(ValidateMeshTest, RejectsInfiniteCoordinate) {
  TriangleMesh mesh = Cube();
  mesh.vertices(0, 2) = -std::numeric_limits<double>::infinity();
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "vertex 0 has a non-finite coordinate");
}

TEST(ValidateMeshTest, RejectsIndexOutOfRangeNamingTriangleAndVertex) {
  TriangleMesh mesh = MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 1, 99}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "triangle 1 references vertex 99 but the mesh has 3 vertices");
}

TEST(ValidateMeshTest, RejectsNegativeIndex) {
  TriangleMesh mesh = MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, -1, 2}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "triangle 0 references vertex -1");
}

TEST(ValidateMeshTest, RejectsTriangleRepeatingAVertex) {
  TriangleMesh mesh = Cube();
  mesh.triangles.row(7) << 1, 6, 1;
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument, "triangle 7 is degenerate");
}

TEST(ValidateMeshTest, RejectsCollinearTriangleAsZeroArea) {
  TriangleMesh mesh =
      MakeMesh({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}}, {{0, 1, 3}, {0, 2, 1}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "triangle 1 is degenerate (zero area)");
}

TEST(ValidateMeshTest, ZeroAreaToleranceIsRelativeToTheBoundingBox) {
  // Area 5e-13 of a unit-sized mesh is tiny but real; scaled by 1e6 nothing changes.
  const std::vector<std::array<double, 3>> vertices = {
      {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1e-12, 0}};
  const std::vector<std::array<int, 3>> triangles = {{0, 1, 2}, {0, 3, 1}};
  TriangleMesh small = MakeMesh(vertices, triangles);
  EXPECT_TRUE(ValidateMesh(small).ok()) << ValidateMesh(small).ToString();
  TriangleMesh large = small;
  large.vertices *= 1e6;
  EXPECT_TRUE(ValidateMesh(large).ok()) << ValidateMesh(large).ToString();
  // Area 5e-15 relative to a unit diagonal squared counts as zero.
  TriangleMesh flat = small;
  flat.vertices(3, 1) = 1e-14;
  EXPECT_STATUS(ValidateMesh(flat), StatusCode::kInvalidArgument, "triangle 1 is degenerate");
}

TEST(ValidateMeshTest, RejectsAllVerticesAtOnePoint) {
  TriangleMesh mesh = MakeMesh({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {{0, 1, 2}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument, "zero area");
}

TEST(ValidateMeshTest, RejectsEdgeSharedByThreeTriangles) {
  TriangleMesh mesh = MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                               {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "edge (0,1) is shared by 3 triangles (non-manifold)");
}

TEST(ValidateMeshTest, RejectsDuplicateTriangleOnAClosedSurface) {
  TriangleMesh mesh;
  mesh.vertices = Cube().vertices;
  mesh.triangles.resize(13, 3);
  mesh.triangles.topRows(12) = Cube().triangles;
  mesh.triangles.row(12) << 4, 5, 6;  // a copy of triangle 2: its edges now have 3 triangles
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "edge (4,5) is shared by 3 triangles (non-manifold)");
}

TEST(ValidateMeshTest, RejectsUnreferencedVertex) {
  TriangleMesh mesh = MakeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}}, {{0, 1, 2}});
  EXPECT_STATUS(ValidateMesh(mesh), StatusCode::kInvalidArgument,
                "vertex 3 is not used by any triangle");
}

TEST(ValidateMeshTest, RejectsMoreVerticesThanTheLimit) {
  MeshLimits limits;
  limits.max_vertices = 7;
  EXPECT_STATUS(ValidateMesh(Cube(), limits), StatusCode::kResourceExhausted, "8 vertices");
}

TEST(ValidateMeshTest, RejectsMoreTrianglesThanTheLimit) {
  MeshLimits limits;
  limits.max_triangles = 11;
  EXPECT_STATUS(ValidateMesh(Cube(), limits), StatusCode::kResourceExhausted, "12 triangles");
}

TEST(ValidateMeshTest, HandlesAMillionVertexGrid) {
  const TriangleMesh mesh = Grid(999);  // 1,000,000 vertices, ~2M triangles
  EXPECT_TRUE(ValidateMesh(mesh).ok());
}

TEST(BoundingBoxDiagonalTest, IsZeroForNoVertices) {
  EXPECT_EQ(BoundingBoxDiagonal(Positions(0, 3)), 0.0);
}

TEST(BoundingBoxDiagonalTest, IsTheBoxDiagonal) {
  EXPECT_DOUBLE_EQ(BoundingBoxDiagonal(Cube().vertices), std::sqrt(3.0));
  EXPECT_DOUBLE_EQ(BoundingBoxDiagonal(Grid(3).vertices), std::sqrt(18.0));
}

// ---------------------------------------------------------------------------------------------
// Format names

TEST(MeshFormatTest, ParsesNamesCaseInsensitivelyWithOrWithoutDot) {
  EXPECT_EQ(*MeshFormatFromName("obj"), MeshFormat::kObj);
  EXPECT_EQ(*MeshFormatFromName(".PLY"), MeshFormat::kPly);
  EXPECT_EQ(*MeshFormatFromName("Stl"), MeshFormat::kStl);
  EXPECT_EQ(*MeshFormatFromName("off"), MeshFormat::kOff);
  EXPECT_EQ(MeshFormatFromName("xyz").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(MeshFormatFromName("").status().code(), StatusCode::kInvalidArgument);
}

TEST(MeshFormatTest, TakesTheFormatFromTheExtension) {
  EXPECT_EQ(*MeshFormatFromPath("/a/b.c/leg.OBJ"), MeshFormat::kObj);
  EXPECT_EQ(*MeshFormatFromPath("mesh.off"), MeshFormat::kOff);
  EXPECT_EQ(MeshFormatFromPath("/a/b.c/mesh").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(MeshFormatFromPath("mesh.txt").status().code(), StatusCode::kInvalidArgument);
}

TEST(MeshFormatTest, NamesRoundTrip) {
  for (MeshFormat format :
       {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff}) {
    EXPECT_EQ(*MeshFormatFromName(MeshFormatName(format)), format);
  }
}

// ---------------------------------------------------------------------------------------------
// Reading: valid input

TEST(ReadMeshTest, ReadsTheCubeInEveryFormat) {
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    const StatusOr<TriangleMesh> mesh = ReadMesh(bytes, format);
    ASSERT_TRUE(mesh.ok()) << MeshFormatName(format) << ": " << mesh.status().ToString();
    EXPECT_EQ(mesh->num_vertices(), 8) << MeshFormatName(format);
    EXPECT_EQ(mesh->num_triangles(), 12) << MeshFormatName(format);
    ExpectSamePositionsToFloatPrecision(SortedPositions(Cube()), SortedPositions(*mesh));
  }
}

TEST(ReadMeshTest, BinaryStlCubeOf36CornersWeldsToEightVertices) {
  const std::string bytes = BinaryStl(Cube());
  ASSERT_EQ(bytes.size(), 84u + 50u * 12u);
  const StatusOr<TriangleMesh> mesh = ReadMesh(bytes, MeshFormat::kStl);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 8);
  EXPECT_EQ(mesh->num_triangles(), 12);
}

TEST(ReadMeshTest, BinaryStlWhoseHeaderStartsWithSolidIsStillBinary) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh(BinaryStl(Cube(), "solid but binary"), MeshFormat::kStl);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 8);
}

TEST(ReadMeshTest, ObjQuadBecomesTwoTriangles) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 4);
  ASSERT_EQ(mesh->num_triangles(), 2);
  EXPECT_EQ(mesh->triangles.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(mesh->triangles.row(1), Eigen::RowVector3i(0, 2, 3));
}

TEST(ReadMeshTest, PlyAndOffQuadsBecomeTwoTriangles) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  const std::string off = "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  const std::vector<std::pair<std::string, MeshFormat>> files = {{ply, MeshFormat::kPly},
                                                                 {off, MeshFormat::kOff}};
  for (const auto& [bytes, format] : files) {
    const StatusOr<TriangleMesh> mesh = ReadMesh(bytes, format);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->num_triangles(), 2);
  }
}

TEST(ReadMeshTest, ObjAcceptsNegativeRelativeIndices) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->triangles.row(0), Eigen::RowVector3i(0, 1, 2));
}

TEST(ReadMeshTest, ObjIgnoresTexturesNormalsGroupsAndMaterialFiles) {
  // OpenMesh would open the mtllib path (here a device that never ends); it must not be passed.
  const std::string obj =
      "# comment\nmtllib /dev/zero\no thing\ng group\ns off\nusemtl none\n"
      "v 0 0 0\nv 1 0 0\nv 0 1 0 1.0\nvt 0 0\nvt 1 0\nvn 0 0 1\n"
      "f 1/1/1 2/2/1 3//1\r\n";
  const StatusOr<TriangleMesh> mesh = ReadMesh(obj, MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_triangles(), 1);
}

TEST(ReadMeshTest, ObjKeepsDoubleInputToFloatPrecision) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh("v 0.1 -2.5e-3 1e-50\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_NEAR(mesh->vertices(0, 0), 0.1, 1e-7);
  EXPECT_NEAR(mesh->vertices(0, 1), -2.5e-3, 1e-9);
  EXPECT_EQ(mesh->vertices(0, 2), 0.0);
}

TEST(ReadMeshTest, PlyWithExtraPropertiesCommentsAndTrailingElementsIsRead) {
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment made by hand\nobj_info nothing\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
      "property uchar red\nproperty float quality\nelement face 1\n"
      "property list uchar int vertex_indices\nproperty uchar red\nelement edge 1\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 255 0.5\n1 0 0 0 255 0.5\n0 1 0 1 255 0.5\n3 0 1 2 7\n2 0 1\n";
  const StatusOr<TriangleMesh> mesh = ReadMesh(ply, MeshFormat::kPly);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 3);
  EXPECT_EQ(mesh->num_triangles(), 1);
}

TEST(ReadMeshTest, BinaryPlyBigEndianAndExtraPropertiesAreRead) {
  BinaryPlyOptions options;
  options.big_endian = true;
  options.extra_vertex_properties = "property float nx\nproperty float confidence\n";
  const StatusOr<TriangleMesh> mesh = ReadMesh(BinaryPly(Cube(), options), MeshFormat::kPly);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  ExpectSamePositionsToFloatPrecision(SortedPositions(Cube()), SortedPositions(*mesh));
  EXPECT_EQ(mesh->triangles, Cube().triangles);
}

TEST(ReadMeshTest, BinaryPlyWithListCountTypesOpenMeshLacksIsRead) {
  // OpenMesh itself refuses "list uint int"; the header is rewritten to an equivalent type.
  for (const std::string count_type : {"uint", "uint32", "int32"}) {
    BinaryPlyOptions options;
    options.count_type = count_type;
    const StatusOr<TriangleMesh> mesh = ReadMesh(BinaryPly(Cube(), options), MeshFormat::kPly);
    ASSERT_TRUE(mesh.ok()) << count_type << ": " << mesh.status().ToString();
    EXPECT_EQ(mesh->triangles, Cube().triangles) << count_type;
  }
}

TEST(ReadMeshTest, PlyWithCrLfHeaderIsRead) {
  std::string bytes = BinaryPly(Cube());
  const std::size_t body = bytes.find("end_header\n") + 11;
  std::string header = bytes.substr(0, body);
  std::string crlf;
  for (char c : header) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const StatusOr<TriangleMesh> mesh = ReadMesh(crlf + bytes.substr(body), MeshFormat::kPly);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 8);
}

// ---------------------------------------------------------------------------------------------
// Reading: malformed input names the problem (and neither hangs nor crashes)

TEST(ReadMeshTest, EmptyDataIsInvalidInEveryFormat) {
  for (MeshFormat format :
       {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff}) {
    EXPECT_STATUS(ReadMesh("", format).status(), StatusCode::kInvalidArgument, "empty");
  }
}

TEST(ReadMeshTest, ObjFaceIndexOutOfRangeIsNamed) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument,
                "line 4: face references vertex 99 but the file has 3 vertices");
}

TEST(ReadMeshTest, ObjFaceIndexZeroIsInvalid) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "vertex index 0 is invalid");
}

TEST(ReadMeshTest, ObjRelativeIndexBeforeFirstVertexIsInvalid) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "relative vertex index -4");
}

TEST(ReadMeshTest, ObjNaNAndInfiniteCoordinatesAreNamed) {
  // OpenMesh silently skips such vertices, shifting every later index.
  for (const std::string value : {"nan", "-inf", "1e999", "INF", "1e39"}) {
    const std::string obj = "v 0 0 0\nv " + value + " 0 0\nv 0 1 0\nf 1 2 3\n";
    EXPECT_STATUS(ReadMesh(obj, MeshFormat::kObj).status(), StatusCode::kInvalidArgument,
                  "vertex 1 has a non-finite coordinate");
  }
}

TEST(ReadMeshTest, ObjMalformedCoordinateIsNamed) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "line 2: vertex 1 has a coordinate that is not");
  EXPECT_STATUS(ReadMesh("v 0 0\n", MeshFormat::kObj).status(), StatusCode::kInvalidArgument,
                "three coordinates");
}

TEST(ReadMeshTest, ObjCornerWithoutVertexIndexIsInvalid) {
  // This aborted OpenMesh's OBJ reader (assertion `!vhandles.empty()`).
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf /1 /2 /3\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "no valid vertex index");
}

TEST(ReadMeshTest, ObjHugeIndexIsInvalid) {
  // OpenMesh silently dropped an unparsable index, leaving "f 1 2 3" here.
  EXPECT_STATUS(
      ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999 3\n", MeshFormat::kObj).status(),
      StatusCode::kInvalidArgument, "no valid vertex index");
}

TEST(ReadMeshTest, ObjFaceRepeatingAVertexIsDegenerate) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "face uses vertex 2 more than once");
}

TEST(ReadMeshTest, ObjCollinearTriangleIsDegenerate) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "triangle 0 is degenerate (zero area)");
}

TEST(ReadMeshTest, ObjFaceWithTwoVerticesIsInvalid) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "at least 3 vertices");
}

TEST(ReadMeshTest, NonManifoldEdgeIsReported) {
  // A halfedge mesh would drop the third face ("complex edge"); the soup keeps it.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
  EXPECT_STATUS(ReadMesh(obj, MeshFormat::kObj).status(), StatusCode::kInvalidArgument,
                "edge (0,1) is shared by 3 triangles (non-manifold)");
}

TEST(ReadMeshTest, UnreferencedVertexIsReported) {
  EXPECT_STATUS(
      ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 9 9 9\nf 1 2 3\n", MeshFormat::kObj).status(),
      StatusCode::kInvalidArgument, "vertex 3 is not used by any triangle");
}

TEST(ReadMeshTest, MeshWithoutFacesIsReported) {
  EXPECT_STATUS(ReadMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\n", MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "no triangles");
  EXPECT_STATUS(ReadMesh("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", MeshFormat::kOff).status(),
                StatusCode::kInvalidArgument, "no triangles");
}

TEST(ReadMeshTest, TruncatedObjIsInvalid) {
  const std::string obj = Obj(Cube());
  // Cut inside the last face line ("f 4 5 8" becomes "f 4 5").
  EXPECT_STATUS(ReadMesh(obj.substr(0, obj.size() - 3), MeshFormat::kObj).status(),
                StatusCode::kInvalidArgument, "at least 3 vertices");
  // Cut inside a vertex line.
  EXPECT_STATUS(
      ReadMesh(obj.substr(0, obj.find("v 0.000000 1.000000") + 10), MeshFormat::kObj).status(),
      StatusCode::kInvalidArgument, "three coordinates");
}

TEST(ReadMeshTest, MoreVerticesThanTheLimitIsResourceExhaustedInEveryFormat) {
  MeshLimits limits;
  limits.max_vertices = 7;
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    EXPECT_STATUS(ReadMesh(bytes, format, limits).status(), StatusCode::kResourceExhausted,
                  "the limit");
  }
}

TEST(ReadMeshTest, MoreTrianglesThanTheLimitIsResourceExhaustedInEveryFormat) {
  MeshLimits limits;
  limits.max_triangles = 11;
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    EXPECT_STATUS(ReadMesh(bytes, format, limits).status(), StatusCode::kResourceExhausted,
                  "the limit");
  }
}

TEST(ReadMeshTest, AbsurdDeclaredCountsAreRefusedBeforeAllocating) {
  const std::string ply_header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  EXPECT_STATUS(ReadMesh(ply_header + std::string(36, '\0'), MeshFormat::kPly).status(),
                StatusCode::kResourceExhausted, "declares 1000000000000 vertices");
  const std::string ply_faces =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 4000000000\n"
      "property list uchar int vertex_indices\nend_header\n";
  EXPECT_STATUS(ReadMesh(ply_faces + std::string(36, '\0'), MeshFormat::kPly).status(),
                StatusCode::kResourceExhausted, "declares 4000000000 faces");
  EXPECT_STATUS(ReadMesh("OFF\n1000000000000 1 0\n0 0 0\n", MeshFormat::kOff).status(),
                StatusCode::kResourceExhausted, "declares 1000000000000 vertices");
}

TEST(ReadMeshTest, TruncatedBinaryStlIsInvalid) {
  const std::string stl = BinaryStl(Cube());
  EXPECT_STATUS(ReadMesh(stl.substr(0, 84 + 50 * 5 + 20), MeshFormat::kStl).status(),
                StatusCode::kInvalidArgument, "truncated");
}

TEST(ReadMeshTest, BinaryStlDeclaringFourBillionTrianglesIsRefusedQuickly) {
  // OpenMesh looped over the declared count (2^32 - 1) however short the data.
  std::string stl = BinaryStl(Cube());
  const std::uint32_t declared = 0xffffffffu;
  std::memcpy(&stl[80], &declared, 4);
  EXPECT_STATUS(ReadMesh(stl, MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "declares 4294967295 triangles");
}

TEST(ReadMeshTest, BinaryStlWithNaNCornerIsInvalid) {
  // OpenMesh's welding map would merge a NaN corner with an arbitrary vertex.
  TriangleMesh mesh = Cube();
  mesh.vertices(6, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_STATUS(ReadMesh(BinaryStl(mesh), MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "non-finite vertex coordinate");
}

TEST(ReadMeshTest, AsciiStlFacetsMustBeTriangles) {
  const std::string stl =
      "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "vertex 5 5 5\nendloop\nendfacet\nendsolid x\n";
  EXPECT_STATUS(ReadMesh(stl, MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "expected 'endloop'");
}

TEST(ReadMeshTest, AsciiStlMalformedVertexLineIsInvalid) {
  // OpenMesh read a blank line as a repeat of the previous vertex.
  const std::string stl =
      "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid x\n";
  EXPECT_STATUS(ReadMesh(stl, MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "STL line 5: expected 'vertex <x> <y> <z>'");
  const std::string nan_stl =
      "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid x\n";
  EXPECT_STATUS(ReadMesh(nan_stl, MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "non-finite");
}

TEST(ReadMeshTest, AsciiStlEndloopLineMustBeExact) {
  // OpenMesh starts a facet at any line containing "outer", so this would misread silently.
  const std::string stl =
      "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop outer\nendfacet\nendsolid x\n";
  EXPECT_STATUS(ReadMesh(stl, MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "expected 'endloop'");
}

TEST(ReadMeshTest, StlThatIsNeitherAsciiNorBinaryIsInvalid) {
  EXPECT_STATUS(ReadMesh("hello", MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "not STL data");
}

TEST(ReadMeshTest, TruncatedBinaryPlyIsInvalid) {
  const std::string ply = BinaryPly(Cube());
  const std::size_t body = ply.find("end_header\n") + 11;
  // Inside the vertices, and inside a face record.
  EXPECT_STATUS(ReadMesh(ply.substr(0, body + 50), MeshFormat::kPly).status(),
                StatusCode::kInvalidArgument, "the PLY data ends inside vertex 4 of 8");
  EXPECT_STATUS(ReadMesh(ply.substr(0, ply.size() - 3), MeshFormat::kPly).status(),
                StatusCode::kInvalidArgument, "the PLY data ends inside face 11 of 12");
}

TEST(ReadMeshTest, PlyHeaderWithoutEndHeaderIsInvalid) {
  // OpenMesh's header loop never ended (and kept allocating) on this.
  EXPECT_STATUS(
      ReadMesh("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", MeshFormat::kPly)
          .status(),
      StatusCode::kInvalidArgument, "no 'end_header'");
}

TEST(ReadMeshTest, PlyPropertyBeforeAnyElementIsInvalid) {
  // This crashed OpenMesh (elements_.back() on an empty vector).
  EXPECT_STATUS(
      ReadMesh("ply\nformat ascii 1.0\nproperty float x\nend_header\n", MeshFormat::kPly).status(),
      StatusCode::kInvalidArgument, "property comes before any element");
}

TEST(ReadMeshTest, PlyDataOnTheEndHeaderLineIsInvalid) {
  EXPECT_STATUS(ReadMesh("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                         "property float y\nproperty float z\nend_header 0 0 0\n1 0 0\n0 1 0\n",
                         MeshFormat::kPly)
                    .status(),
                StatusCode::kInvalidArgument, "'end_header' must stand alone");
}

TEST(ReadMeshTest, PlyUnsupportedLayoutsAreNamed) {
  const std::string start =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\n";
  const std::string body(36 + 13, '\0');
  EXPECT_STATUS(
      ReadMesh(start + "property list uchar float normals\nend_header\n" + body, MeshFormat::kPly)
          .status(),
      StatusCode::kInvalidArgument, "it is a list");
  EXPECT_STATUS(ReadMesh(start +
                             "element face 1\nproperty uchar flags\n"
                             "property list uchar int vertex_indices\nend_header\n" +
                             body,
                         MeshFormat::kPly)
                    .status(),
                StatusCode::kInvalidArgument, "must start with a 'vertex_indices' list");
  EXPECT_STATUS(ReadMesh("ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\n"
                         "property float y\nproperty float z\nend_header\n1 2 3\n",
                         MeshFormat::kPly)
                    .status(),
                StatusCode::kInvalidArgument, "must be float or double");
  EXPECT_STATUS(ReadMesh("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n"
                         "end_header\n1\n",
                         MeshFormat::kPly)
                    .status(),
                StatusCode::kInvalidArgument, "unknown type 'half'");
  EXPECT_STATUS(
      ReadMesh("ply\nformat ascii 2.0\nelement face 0\nend_header\n", MeshFormat::kPly).status(),
      StatusCode::kInvalidArgument, "no vertex element");
}

TEST(ReadMeshTest, PlyNegativeOrHugeListSizeIsInvalid) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list int int vertex_indices\nend_header\n";
  std::string vertices;
  for (float value : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) AppendRaw(&vertices, value);
  std::string negative;
  AppendRaw(&negative, std::int32_t{-1});
  EXPECT_STATUS(ReadMesh(header + vertices + negative, MeshFormat::kPly).status(),
                StatusCode::kInvalidArgument, "invalid list size -1");
  std::string huge;
  AppendRaw(&huge, std::int32_t{0x7fffffff});
  EXPECT_STATUS(
      ReadMesh(header + vertices + huge + std::string(12, '\0'), MeshFormat::kPly).status(),
      StatusCode::kInvalidArgument, "ends inside face 0 of 1");
}

TEST(ReadMeshTest, PlyNonFiniteCoordinatesAreNamed) {
  std::string ascii = AsciiPly(Cube());
  ascii.replace(ascii.find("1.000000 1.000000 1.000000"), 8, "nan");
  EXPECT_STATUS(ReadMesh(ascii, MeshFormat::kPly).status(), StatusCode::kInvalidArgument,
                "vertex 6 has a non-finite coordinate");
  TriangleMesh mesh = Cube();
  mesh.vertices(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_STATUS(ReadMesh(BinaryPly(mesh), MeshFormat::kPly).status(), StatusCode::kInvalidArgument,
                "vertex 2 has a non-finite coordinate");
}

TEST(ReadMeshTest, PlyFaceIndexOutOfRangeIsNamed) {
  std::string ascii = AsciiPly(Cube());
  ascii.replace(ascii.rfind("3 3 4 7"), 7, "3 3 4 70");
  EXPECT_STATUS(ReadMesh(ascii, MeshFormat::kPly).status(), StatusCode::kInvalidArgument,
                "face 11 references vertex 70 but the mesh has 8 vertices");
}

TEST(ReadMeshTest, TruncatedOffWithHugeFaceCountIsInvalid) {
  // OpenMesh looped over the declared face count without looking for the end of the data.
  EXPECT_STATUS(
      ReadMesh("OFF\n3 4000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::kOff).status(),
      StatusCode::kInvalidArgument, "ends inside face 1 of 4000000");
}

TEST(ReadMeshTest, OffVariantsAndFaceColoursAreInvalid) {
  EXPECT_STATUS(
      ReadMesh("COFF\n3 1 0\n0 0 0 1 1 1\n1 0 0 1 1 1\n0 1 0 1 1 1\n3 0 1 2\n", MeshFormat::kOff)
          .status(),
      StatusCode::kInvalidArgument, "exactly 'OFF'");
  EXPECT_STATUS(
      ReadMesh("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255 0 0\n", MeshFormat::kOff).status(),
      StatusCode::kInvalidArgument, "face colours are not supported");
  EXPECT_STATUS(ReadMesh("OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n", MeshFormat::kOff).status(),
                StatusCode::kInvalidArgument, "vertex 1 has a non-finite coordinate");
}

// Random bytes, alone and after each format's magic, in every format.
TEST(ReadMeshTest, GarbageBytesAreInvalidNotACrash) {
  std::mt19937 random(1234);
  for (int trial = 0; trial < 40; ++trial) {
    std::string garbage(1 + random() % 600, '\0');
    for (char& c : garbage) c = static_cast<char>(random());
    for (const std::string prefix :
         {"", "ply\n", "ply\nformat ascii 1.0\n", "OFF\n", "solid ", "v 1 2 3\nf "}) {
      for (MeshFormat format :
           {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff}) {
        const StatusOr<TriangleMesh> mesh = ReadMesh(prefix + garbage, format);
        EXPECT_FALSE(mesh.ok());
      }
    }
  }
}

// Every prefix of every valid cube file either reads or fails cleanly; binary cuts always fail.
TEST(ReadMeshTest, EveryTruncationOfAValidFileIsHandled) {
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    for (std::size_t size = 0; size < bytes.size(); ++size) {
      const StatusOr<TriangleMesh> mesh = ReadMesh(bytes.substr(0, size), format);
      if (mesh.ok()) {
        EXPECT_TRUE(ValidateMesh(*mesh).ok());
      } else {
        EXPECT_NE(mesh.status().code(), StatusCode::kOk);
      }
    }
  }
  const std::string binary_ply = BinaryPly(Cube());
  const std::string binary_stl = BinaryStl(Cube());
  for (std::size_t size = 0; size < binary_ply.size(); ++size) {
    EXPECT_FALSE(ReadMesh(binary_ply.substr(0, size), MeshFormat::kPly).ok()) << size;
  }
  for (std::size_t size = 0; size < binary_stl.size(); ++size) {
    EXPECT_FALSE(ReadMesh(binary_stl.substr(0, size), MeshFormat::kStl).ok()) << size;
  }
}

// Every byte of every valid cube file overwritten with a few values: no crash, no hang.
TEST(ReadMeshTest, CorruptedBytesAreHandled) {
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      for (const char value : {'\0', '\xff', '\x80', '9', '-', '\n', ' '}) {
        std::string corrupted = bytes;
        corrupted[i] = value;
        const StatusOr<TriangleMesh> mesh = ReadMesh(corrupted, format);
        if (mesh.ok()) {
          EXPECT_TRUE(ValidateMesh(*mesh).ok());
        }
      }
    }
  }
}

TEST(ReadMeshTest, ConcurrentReadsAreSafe) {
  std::vector<std::thread> threads;
  std::vector<int> failures(4, 0);
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([i, &failures] {
      const auto files = ValidCubeFiles();
      for (int round = 0; round < 50; ++round) {
        for (const auto& [bytes, format] : files) {
          if (!ReadMesh(bytes, format).ok()) ++failures[i];
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures, std::vector<int>(4, 0));
}

// ---------------------------------------------------------------------------------------------
// Files

class MeshFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = std::filesystem::temp_directory_path() /
                 ("deform_mesh_io_test_" + std::to_string(::getpid()) + "_" + test->name());
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string PathOf(const std::string& name) const { return (directory_ / name).string(); }
  std::string WriteBytes(const std::string& name, const std::string& bytes) const {
    const std::string path = PathOf(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::filesystem::path directory_;
};

TEST_F(MeshFileTest, RoundTripPreservesCountsAndPositionsInEveryFormat) {
  const TriangleMesh original = SkewedCube();
  for (const std::string extension : {"obj", "ply", "off", "stl", "OBJ"}) {
    const std::string path = PathOf("mesh." + extension);
    ASSERT_TRUE(WriteMeshFile(original, path).ok()) << path;
    const StatusOr<TriangleMesh> read = ReadMeshFile(path);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    EXPECT_EQ(read->num_vertices(), original.num_vertices()) << extension;
    EXPECT_EQ(read->num_triangles(), original.num_triangles()) << extension;
    ExpectSamePositionsToFloatPrecision(SortedPositions(original), SortedPositions(*read));
    if (extension != "stl") {  // STL welding renumbers vertices
      EXPECT_EQ(read->triangles, original.triangles) << extension;
      ExpectSamePositionsToFloatPrecision(PositionList(original), PositionList(*read));
    }
  }
}

TEST_F(MeshFileTest, OpenGridRoundTripsThroughBinaryPly) {
  const TriangleMesh original = Grid(20);
  const std::string path = PathOf("grid.ply");
  ASSERT_TRUE(WriteMeshFile(original, path).ok());
  const StatusOr<TriangleMesh> read = ReadMeshFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->vertices, original.vertices);  // small integers are exact in float
  EXPECT_EQ(read->triangles, original.triangles);
}

TEST_F(MeshFileTest, WrittenPlyAndStlAreBinary) {
  ASSERT_TRUE(WriteMeshFile(Cube(), PathOf("cube.ply")).ok());
  ASSERT_TRUE(WriteMeshFile(Cube(), PathOf("cube.stl")).ok());
  std::ifstream ply(PathOf("cube.ply"), std::ios::binary);
  const std::string ply_bytes((std::istreambuf_iterator<char>(ply)), {});
  EXPECT_THAT(ply_bytes, HasSubstr("format binary_little_endian 1.0"));
  EXPECT_EQ(std::filesystem::file_size(PathOf("cube.stl")), 84u + 50u * 12u);
}

TEST_F(MeshFileTest, MissingFileIsNotFound) {
  EXPECT_STATUS(ReadMeshFile(PathOf("absent.obj")).status(), StatusCode::kNotFound, "absent.obj");
}

TEST_F(MeshFileTest, DirectoryIsInvalid) {
  std::filesystem::create_directories(PathOf("folder.obj"));
  EXPECT_STATUS(ReadMeshFile(PathOf("folder.obj")).status(), StatusCode::kInvalidArgument,
                "directory");
}

TEST_F(MeshFileTest, UnknownExtensionIsInvalid) {
  EXPECT_STATUS(ReadMeshFile(WriteBytes("mesh.xyz", "v 0 0 0\n")).status(),
                StatusCode::kInvalidArgument, "unknown mesh format");
  EXPECT_STATUS(WriteMeshFile(Cube(), PathOf("mesh.xyz")), StatusCode::kInvalidArgument,
                "unknown mesh format");
}

TEST_F(MeshFileTest, ReadErrorsNameTheFile) {
  const std::string path = WriteBytes("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
  EXPECT_STATUS(ReadMeshFile(path).status(), StatusCode::kInvalidArgument, path + ": OBJ line 4");
}

TEST_F(MeshFileTest, EmptyFileIsInvalid) {
  EXPECT_STATUS(ReadMeshFile(WriteBytes("empty.ply", "")).status(), StatusCode::kInvalidArgument,
                "empty");
}

TEST_F(MeshFileTest, WritingIntoMissingDirectoryIsNotFoundAndNamesThePath) {
  const std::string path = PathOf("no/such/dir/mesh.obj");
  EXPECT_STATUS(WriteMeshFile(Cube(), path), StatusCode::kNotFound, path);
}

TEST_F(MeshFileTest, WritingAMeshWithBadIndicesOrNaNIsInvalid) {
  TriangleMesh bad_index = Cube();
  bad_index.triangles(3, 1) = 8;
  EXPECT_STATUS(WriteMeshFile(bad_index, PathOf("a.stl")), StatusCode::kInvalidArgument,
                "triangle 3 references vertex 8");
  TriangleMesh nan = Cube();
  nan.vertices(2, 0) = std::nan("");
  EXPECT_STATUS(WriteMeshFile(nan, PathOf("b.obj")), StatusCode::kInvalidArgument,
                "vertex 2 has a non-finite coordinate");
}

// ---------------------------------------------------------------------------------------------
// Shared meshes

TEST(SharedMeshTest, ReadsTheOpenLeg) {
  DEFORM_REQUIRE_SHARED_FILE(path, "leg/leg_1633.obj");
  const StatusOr<TriangleMesh> mesh = ReadMeshFile(path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 1633);
  EXPECT_EQ(mesh->num_triangles(), 3240);
}

TEST(SharedMeshTest, ReadsTheArm) {
  DEFORM_REQUIRE_SHARED_FILE(path, "arm/arm_8311.obj");
  const StatusOr<TriangleMesh> mesh = ReadMeshFile(path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 8311);
  EXPECT_EQ(mesh->num_triangles(), 16618);
}

}  // namespace
}  // namespace deform
