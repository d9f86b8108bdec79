// Tests of reading PLY data (core/mesh_io.h): what is read, and malformed input named.
//
// Malformed inputs are written as bytes in the tests themselves. Many of them used to hang, abort
// or crash OpenMesh's PLY reader before the checks in mesh_io_ply.cc; each is noted below.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "core/io/mesh_io.h"
#include "tests/core/io/mesh_io_test_util.h"

namespace deform::mesh_io_test {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading: valid input

TEST(ReadMeshTest, PlyWithExtraPropertiesCommentsAndTrailingElementsIsRead) {
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment made by hand\nobj_info nothing\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
      "property uchar red\nproperty float quality\nelement face 1\n"
      "property list uchar int vertex_indices\nproperty uchar red\nelement edge 1\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 255 0.5\n1 0 0 0 255 0.5\n0 1 0 1 255 0.5\n3 0 1 2 7\n2 0 1\n";
  ExpectMeshSize(ReadMesh(ply, MeshFormat::kPly), 3, 1);
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

TEST(ReadMeshTest, TruncatedBinaryPlyIsInvalid) {
  const std::string ply = BinaryPly(Cube());
  const std::size_t body = ply.find("end_header\n") + 11;
  // Inside the vertices, and inside a face record.
  EXPECT_STATUS(ReadMesh(ply.substr(0, body + 50), MeshFormat::kPly).status(),
                StatusCode::kInvalidArgument, "the PLY data ends inside vertex 4 of 8");
  EXPECT_STATUS(ReadMesh(ply.substr(0, ply.size() - 3), MeshFormat::kPly).status(),
                StatusCode::kInvalidArgument, "the PLY data ends inside face 11 of 12");
}

TEST(ReadMeshTest, MalformedPlyHeadersAndUnsupportedLayoutsAreNamed) {
  const std::string xyz =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\n";
  const std::string body(36 + 13, '\0');
  ExpectRefusals(
      MeshFormat::kPly,
      {// OpenMesh's header loop never ended (and kept allocating) on this.
       {"no end_header", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
        "no 'end_header'"},
       // This crashed OpenMesh (elements_.back() on an empty vector).
       {"a property before any element", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
        "property comes before any element"},
       {"data on the end_header line",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header 0 0 0\n1 0 0\n0 1 0\n",
        "'end_header' must stand alone"},
       {"a vertex list property", xyz + "property list uchar float normals\nend_header\n" + body,
        "it is a list"},
       {"a face element not starting with the indices",
        xyz +
            "element face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\n"
            "end_header\n" +
            body,
        "must start with a 'vertex_indices' list"},
       {"an integer coordinate",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\n"
        "property float z\nend_header\n1 2 3\n",
        "must be float or double"},
       {"an unknown type",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n1\n",
        "unknown type 'half'"},
       {"no vertex element", "ply\nformat ascii 2.0\nelement face 0\nend_header\n",
        "no vertex element"}});
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

}  // namespace
}  // namespace deform::mesh_io_test
