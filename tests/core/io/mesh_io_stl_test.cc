// Tests of reading STL data (core/mesh_io.h): what is read, and malformed input named.
//
// Malformed inputs are written as bytes in the tests themselves. Many of them used to hang, abort
// or crash OpenMesh's STL reader before the checks in mesh_io_stl.cc; each is noted below.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "core/io/mesh_io.h"
#include "tests/core/io/mesh_io_test_util.h"

namespace deform::mesh_io_test {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading: valid input

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

// ---------------------------------------------------------------------------------------------
// Reading: malformed input names the problem (and neither hangs nor crashes)

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

}  // namespace
}  // namespace deform::mesh_io_test
