// Tests of mesh validation (core/mesh.h) and of mesh reading and writing (core/mesh_io.h) across
// formats: format names, what every reader must do with valid, limited or garbage input, files.
// Each format's own cases are in mesh_io_<format>_test.cc.
//
// Malformed inputs are written as bytes in the tests themselves. Where one used to hang, abort or
// crash OpenMesh's readers before the checks in mesh_io_<format>.cc, it is noted.
#include "core/io/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/geometry/mesh.h"
#include "tests/core/io/mesh_io_test_util.h"
#include "tests/shared_data.h"

namespace deform::mesh_io_test {
namespace {

using ::testing::HasSubstr;

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
// Reading: every format

TEST(ReadMeshTest, ReadsTheCubeInEveryFormat) {
  for (const auto& [bytes, format] : ValidCubeFiles()) {
    const StatusOr<TriangleMesh> mesh = ReadMesh(bytes, format);
    ASSERT_TRUE(mesh.ok()) << MeshFormatName(format) << ": " << mesh.status().ToString();
    EXPECT_EQ(mesh->num_vertices(), 8) << MeshFormatName(format);
    EXPECT_EQ(mesh->num_triangles(), 12) << MeshFormatName(format);
    ExpectSamePositionsToFloatPrecision(SortedPositions(Cube()), SortedPositions(*mesh));
  }
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

TEST(ReadMeshTest, EmptyDataIsInvalidInEveryFormat) {
  for (MeshFormat format :
       {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff}) {
    EXPECT_STATUS(ReadMesh("", format).status(), StatusCode::kInvalidArgument, "empty");
  }
}

TEST(ReadMeshTest, MoreVerticesOrTrianglesThanTheLimitIsResourceExhaustedInEveryFormat) {
  MeshLimits few_vertices;
  few_vertices.max_vertices = 7;
  MeshLimits few_triangles;
  few_triangles.max_triangles = 11;
  for (const MeshLimits& limits : {few_vertices, few_triangles}) {
    for (const auto& [bytes, format] : ValidCubeFiles()) {
      EXPECT_STATUS(ReadMesh(bytes, format, limits).status(), StatusCode::kResourceExhausted,
                    "the limit");
    }
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
// Reading: what was read is validated

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
  ExpectMeshSize(ReadMeshFile(path), 1633, 3240);
}

TEST(SharedMeshTest, ReadsTheArm) {
  DEFORM_REQUIRE_SHARED_FILE(path, "arm/arm_8311.obj");
  ExpectMeshSize(ReadMeshFile(path), 8311, 16618);
}

}  // namespace
}  // namespace deform::mesh_io_test
