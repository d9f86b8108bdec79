// Tests of reading OBJ data (core/mesh_io.h): what is read, and malformed input named.
//
// Malformed inputs are written as bytes in the tests themselves. Many of them used to hang, abort
// or crash OpenMesh's OBJ reader before the checks in mesh_io_obj.cc; each is noted below.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/io/mesh_io.h"
#include "tests/core/io/mesh_io_test_util.h"

namespace deform::mesh_io_test {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading: valid input

TEST(ReadMeshTest, ObjQuadBecomesTwoTriangles) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->num_vertices(), 4);
  ASSERT_EQ(mesh->num_triangles(), 2);
  EXPECT_EQ(mesh->triangles.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(mesh->triangles.row(1), Eigen::RowVector3i(0, 2, 3));
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
  ExpectMeshSize(ReadMesh(obj, MeshFormat::kObj), 3, 1);
}

TEST(ReadMeshTest, ObjKeepsDoubleInputToFloatPrecision) {
  const StatusOr<TriangleMesh> mesh =
      ReadMesh("v 0.1 -2.5e-3 1e-50\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_NEAR(mesh->vertices(0, 0), 0.1, 1e-7);
  EXPECT_NEAR(mesh->vertices(0, 1), -2.5e-3, 1e-9);
  EXPECT_EQ(mesh->vertices(0, 2), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Reading: malformed input names the problem (and neither hangs nor crashes)

TEST(ReadMeshTest, MalformedObjIsNamed) {
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::vector<Refusal> refusals = {
      {"face index out of range", triangle + "f 1 2 99\n",
       "line 4: face references vertex 99 but the file has 3 vertices"},
      {"face index zero", triangle + "f 0 1 2\n", "vertex index 0 is invalid"},
      {"relative index before the first vertex", triangle + "f -1 -2 -4\n",
       "relative vertex index -4"},
      {"malformed coordinate", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n",
       "line 2: vertex 1 has a coordinate that is not"},
      {"two coordinates", "v 0 0\n", "three coordinates"},
      // This aborted OpenMesh's OBJ reader (assertion `!vhandles.empty()`).
      {"corner without vertex index", triangle + "f /1 /2 /3\n", "no valid vertex index"},
      // OpenMesh silently dropped an unparsable index, leaving "f 1 2 3" here.
      {"huge index", triangle + "f 1 2 99999999999 3\n", "no valid vertex index"},
      {"face repeating a vertex", triangle + "f 1 2 2\n", "face uses vertex 2 more than once"},
      {"collinear triangle", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
       "triangle 0 is degenerate (zero area)"},
      {"face with two vertices", triangle + "f 1 2\n", "at least 3 vertices"},
  };
  // OpenMesh silently skips vertices with NaN or infinite coordinates, shifting every later index.
  for (const std::string value : {"nan", "-inf", "1e999", "INF", "1e39"}) {
    refusals.push_back({"coordinate " + value, "v 0 0 0\nv " + value + " 0 0\nv 0 1 0\nf 1 2 3\n",
                        "vertex 1 has a non-finite coordinate"});
  }
  ExpectRefusals(MeshFormat::kObj, refusals);
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

}  // namespace
}  // namespace deform::mesh_io_test
