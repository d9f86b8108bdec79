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
  ExpectMeshSize(ReadMesh(bytes, MeshFormat::kStl), 8, 12);
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

TEST(ReadMeshTest, MalformedAsciiStlIsNamed) {
  const std::string facet_start = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
  const std::string facet_end = "endloop\nendfacet\nendsolid x\n";
  ExpectRefusals(
      MeshFormat::kStl,
      {{"a facet of four vertices",
        facet_start + "vertex 1 0 0\nvertex 0 1 0\nvertex 5 5 5\n" + facet_end,
        "expected 'endloop'"},
       // OpenMesh read a blank line as a repeat of the previous vertex.
       {"a blank vertex line", facet_start + "\nvertex 1 0 0\nvertex 0 1 0\n" + facet_end,
        "STL line 5: expected 'vertex <x> <y> <z>'"},
       {"a NaN coordinate", facet_start + "vertex nan 0 0\nvertex 0 1 0\n" + facet_end,
        "non-finite"},
       // OpenMesh starts a facet at any line containing "outer", so this would misread silently.
       {"an endloop line with more on it",
        facet_start + "vertex 1 0 0\nvertex 0 1 0\nendloop outer\nendfacet\nendsolid x\n",
        "expected 'endloop'"}});
}

TEST(ReadMeshTest, StlThatIsNeitherAsciiNorBinaryIsInvalid) {
  EXPECT_STATUS(ReadMesh("hello", MeshFormat::kStl).status(), StatusCode::kInvalidArgument,
                "not STL data");
}

}  // namespace
}  // namespace deform::mesh_io_test
