// ReadDeclaredMeshSize: the counts each format declares before its data, and nothing (never a
// failure) from bytes that declare nothing readable.
#include "core/io/declared_mesh_size.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace deform {
namespace {

void ExpectSize(const std::string& bytes, MeshFormat format, std::size_t vertices,
                std::size_t faces) {
  const auto size = ReadDeclaredMeshSize(bytes, format);
  ASSERT_TRUE(size.has_value()) << bytes.substr(0, 40);
  EXPECT_EQ(size->vertices, vertices);
  EXPECT_EQ(size->faces, faces);
}

TEST(DeclaredMeshSize, OffCountsWithCommentsAndOnTheKeywordLine) {
  ExpectSize("OFF\n# a comment\n\n8 12 0\n0 0 0\n", MeshFormat::kOff, 8, 12);
  ExpectSize("OFF 1000000 2000000 0\n", MeshFormat::kOff, 1000000, 2000000);
  ExpectSize("COFF\r\n3 1 0\r\n", MeshFormat::kOff, 3, 1);
}

TEST(DeclaredMeshSize, PlyHeaderElementsAsciiAndBinary) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment made by a test\nelement vertex 26000\n"
      "property float x\nproperty float y\nproperty float z\nelement face 52000\n"
      "property list uchar int vertex_indices\nend_header\n";
  ExpectSize(header + std::string("\x01\x02\x03\x00\xff", 5), MeshFormat::kPly, 26000, 52000);
}

TEST(DeclaredMeshSize, BinaryStlCountMustMatchItsSize) {
  std::string stl(84 + 2 * 50, '\0');
  stl[80] = 2;  // two triangles, little-endian
  ExpectSize(stl, MeshFormat::kStl, 6, 2);
  stl[80] = 3;  // the count no longer matches the size: not believed
  EXPECT_FALSE(ReadDeclaredMeshSize(stl, MeshFormat::kStl).has_value());
}

TEST(DeclaredMeshSize, AsciiStlFacetsAndObjLinesAreCounted) {
  ExpectSize(
      "solid s\n facet normal 0 0 1\n  outer loop\n endloop\n endfacet\n"
      " facet normal 0 0 1\n endfacet\nendsolid s\n",
      MeshFormat::kStl, 6, 2);
  ExpectSize("# obj\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nvt 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj, 3,
             1);
}

TEST(DeclaredMeshSize, NothingReadableGivesNothing) {
  for (const char* bytes : {"", "OFF\n", "OFF\nmany few 0\n", "OFF\n99999999999999999999 1 0\n",
                            "not a mesh", "ply\nelement vertex\nend_header\n"}) {
    EXPECT_FALSE(ReadDeclaredMeshSize(bytes, MeshFormat::kOff).has_value()) << bytes;
    EXPECT_FALSE(ReadDeclaredMeshSize(bytes, MeshFormat::kPly).has_value()) << bytes;
  }
  EXPECT_FALSE(ReadDeclaredMeshSize("# only a comment\n", MeshFormat::kObj).has_value());
}

}  // namespace
}  // namespace deform
