#include "core/io/skin_weights_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/skeleton_io.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

// Bytes of a binary DMAT of `cols` x `rows` holding `values` (column-major).
std::string BinaryDmat(int cols, int rows, const std::vector<double>& values) {
  std::string bytes = "0 0\n" + std::to_string(cols) + " " + std::to_string(rows) + "\n";
  for (double value : values) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    for (int b = 0; b < 8; ++b) bytes.push_back(static_cast<char>((bits >> (8 * b)) & 0xff));
  }
  return bytes;
}

// The weight of `bone` at `vertex`, 0 when the vertex has no entry for it.
double WeightOf(const SkinWeights& weights, int vertex, int bone) {
  double total = 0;
  for (int e = weights.offsets[vertex]; e < weights.offsets[vertex + 1]; ++e) {
    if (weights.bones[e] == bone) total += weights.weights[e];
  }
  return total;
}

void ExpectRefused(std::string_view bytes, SkinWeightsFormat format, StatusCode code,
                   const std::string& needle) {
  auto result = ReadSkinWeights(bytes, format);
  ASSERT_FALSE(result.ok()) << "accepted: " << bytes.substr(0, 40);
  EXPECT_EQ(result.status().code(), code) << result.status().ToString();
  EXPECT_NE(result.status().message().find(needle), std::string::npos)
      << "'" << needle << "' not in: " << result.status().message();
}

TEST(SkinWeightsFormat, ComesFromTheExtension) {
  EXPECT_EQ(*SkinWeightsFormatFromPath("a/arm_weights.DMAT"), SkinWeightsFormat::kDmat);
  EXPECT_EQ(*SkinWeightsFormatFromPath("w.csv"), SkinWeightsFormat::kCsv);
  EXPECT_EQ(SkinWeightsFormatFromPath("w.txt").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(SkinWeightsFormatFromPath("weights").status().code(), StatusCode::kInvalidArgument);
}

TEST(ReadDmat, ReadsAsciiColumnMajor) {
  // 2 bones (columns) x 3 vertices (rows): column 0 = 1, 0.25, 0; column 1 = 0, 0.75, 1.
  auto weights = ReadSkinWeights("2 3\n1\n0.25\n0\n0 0.75 1\n", SkinWeightsFormat::kDmat);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->num_vertices(), 3);
  EXPECT_EQ(weights->num_bones, 2);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 0, 0), 1.0);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 1, 0), 0.25);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 1, 1), 0.75);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 2, 1), 1.0);
  EXPECT_EQ(weights->bones.size(), 4u);  // zeros dropped
}

TEST(ReadDmat, ReadsBinary) {
  auto weights =
      ReadSkinWeights(BinaryDmat(2, 3, {1, 0.25, 0, 0, 0.75, 1}), SkinWeightsFormat::kDmat);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->num_vertices(), 3);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 1, 1), 0.75);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 2, 1), 1.0);
}

TEST(ReadDmat, ReadsNegativeRoundOffAsZero) {
  auto weights = ReadSkinWeights("1 2\n1 -1e-15\n", SkinWeightsFormat::kDmat);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->offsets, (std::vector<int>{0, 1, 1}));
}

TEST(ReadDmat, RefusesMalformedInput) {
  constexpr auto kDmat = SkinWeightsFormat::kDmat;
  constexpr auto kInvalid = StatusCode::kInvalidArgument;
  ExpectRefused("", kDmat, kInvalid, "empty");
  ExpectRefused("two 3\n1 2 3\n", kDmat, kInvalid, "'cols rows'");
  ExpectRefused("2 3 4\n", kDmat, kInvalid, "'cols rows'");
  ExpectRefused("-2 3\n", kDmat, kInvalid, "negative");
  ExpectRefused("0 3\n", kDmat, kInvalid, "at least one bone");
  ExpectRefused("2 3\n1 0 0 0 1\n", kDmat, kInvalid, "ends after 5 of 6 values");
  ExpectRefused("1 2\n1 0 7\n", kDmat, kInvalid, "more values");
  ExpectRefused("1 2\n1 x\n", kDmat, kInvalid, "row 1, column 0 (line 2) is not a number");
  ExpectRefused("1 2\n1 nan\n", kDmat, kInvalid, "not finite");
  ExpectRefused("2 1\n1 -0.5\n", kDmat, kInvalid, "negative weight");
  // Binary: truncated data, extra data, a missing size line, NaN.
  std::string binary = BinaryDmat(2, 3, {1, 0.25, 0, 0, 0.75, 1});
  ExpectRefused(std::string_view(binary).substr(0, binary.size() - 3), kDmat, kInvalid, "bytes");
  ExpectRefused(binary + "x", kDmat, kInvalid, "bytes of data");
  ExpectRefused("0 0\n", kDmat, kInvalid, "no size line");
  ExpectRefused("0 0\n2 3", kDmat, kInvalid, "ends inside its size line");
  ExpectRefused(BinaryDmat(1, 1, {std::nan("")}), kDmat, kInvalid, "not finite");
}

TEST(ReadDmat, RefusesAbsurdSizesWithoutAllocatingThem) {
  constexpr auto kDmat = SkinWeightsFormat::kDmat;
  // cols * rows overflows 32 and 64 bits; far beyond the data; beyond the limits.
  ExpectRefused("4294967296 4294967296\n1\n", kDmat, StatusCode::kResourceExhausted, "limit");
  ExpectRefused("99999999999999999999 1\n1\n", kDmat, StatusCode::kInvalidArgument, "cols rows");
  ExpectRefused("4 1000000\n1 2 3\n", kDmat, StatusCode::kInvalidArgument,
                "4 x 1000000 = 4000000 values but holds only");
  ExpectRefused("0 0\n65536 2000000\n", kDmat, StatusCode::kInvalidArgument, "values but holds");
  ExpectRefused("1 3000000\n1\n", kDmat, StatusCode::kResourceExhausted, "rows (vertices)");
  ExpectRefused("70000 1\n1\n", kDmat, StatusCode::kResourceExhausted, "columns (bones)");
  MeshLimits small;
  small.max_vertices = 2;
  auto limited = ReadSkinWeights("1 3\n1 1 1\n", kDmat, small);
  EXPECT_EQ(limited.status().code(), StatusCode::kResourceExhausted);
}

TEST(ReadWeightsCsv, ReadsSparseLinesWithHeaderCommentsAndBlanks) {
  auto weights = ReadSkinWeights(
      "vertex,bone,weight\n"
      "# exported by hand\n"
      "0,0,1\n"
      "\n"
      "2, 1, 0.5\r\n"
      "2,0,0.5\n"
      "1,1,1.0\n",
      SkinWeightsFormat::kCsv);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->num_vertices(), 3);
  EXPECT_EQ(weights->num_bones, 2);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 0, 0), 1.0);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 1, 1), 1.0);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 2, 0), 0.5);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 2, 1), 0.5);
}

TEST(ReadWeightsCsv, RefusesMalformedInput) {
  constexpr auto kCsv = SkinWeightsFormat::kCsv;
  constexpr auto kInvalid = StatusCode::kInvalidArgument;
  ExpectRefused("", kCsv, kInvalid, "no weights");
  ExpectRefused("vertex,bone,weight\n# nothing\n", kCsv, kInvalid, "no weights");
  ExpectRefused("0,0\n", kCsv, kInvalid, "line 1: expected 'vertex,bone,weight'");
  ExpectRefused("0,0,1\nvertex,bone,weight\n", kCsv, kInvalid, "line 2: the vertex index");
  ExpectRefused("0,0,1,2\n", kCsv, kInvalid, "4 field(s)");
  ExpectRefused("-1,0,1\n", kCsv, kInvalid, "negative vertex");
  ExpectRefused("0,1.5,1\n", kCsv, kInvalid, "bone index is not an integer");
  ExpectRefused("0,0,heavy\n", kCsv, kInvalid, "not a number");
  ExpectRefused("0,0,inf\n", kCsv, kInvalid, "not finite");
  ExpectRefused("0,0,-0.2\n", kCsv, kInvalid, "negative weight");
  ExpectRefused("0,70000,1\n", kCsv, StatusCode::kResourceExhausted, "bone index 70000");
  ExpectRefused("99999999,0,1\n", kCsv, StatusCode::kResourceExhausted, "vertex index 99999999");
}

TEST(LoadSkinWeightsFile, WidensACsvToTheSkeletonAndNormalizes) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "deform_weights_widen_test.csv").string();
  {
    std::ofstream out(path);
    out << "0,0,2\n1,0,1\n1,1,3\n";
  }
  auto weights = LoadSkinWeightsFile(path, 2, 4);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->num_bones, 4);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 0, 0), 1.0);
  EXPECT_DOUBLE_EQ(WeightOf(*weights, 1, 1), 0.75);
  // A mesh of three vertices: the third follows no bone.
  auto missing = LoadSkinWeightsFile(path, 3, 4);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("vertex 2 sum to 0"), std::string::npos)
      << missing.status().message();
  std::filesystem::remove(path);
  EXPECT_EQ(LoadSkinWeightsFile(path, 3, 4).status().code(), StatusCode::kNotFound);
}

// The arm's authored weights: one row per vertex of the mesh of that size, one column per bone of
// arm.tgf; each row sums to one after normalization.
void CheckSharedArmWeights(const std::string& mesh_path, const std::string& weights_path,
                           int expected_rows) {
  auto mesh = ReadMeshFile(mesh_path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  auto skeleton = ReadSkeletonFile(test_support::SharedDataFile("arm/arm.tgf"));
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  auto raw = ReadSkinWeightsFile(weights_path);
  ASSERT_TRUE(raw.ok()) << raw.status().ToString();
  EXPECT_EQ(raw->num_vertices(), expected_rows);
  EXPECT_EQ(raw->num_bones, 4);
  EXPECT_EQ(raw->num_bones, skeleton->num_bones());
  EXPECT_EQ(mesh->num_vertices(), expected_rows);
  auto normalized = NormalizeSkinWeights(*raw, mesh->num_vertices(), skeleton->num_bones());
  ASSERT_TRUE(normalized.ok()) << normalized.status().ToString();
  double worst = 0;
  for (int v = 0; v < normalized->num_vertices(); ++v) {
    double total = 0;
    for (int e = normalized->offsets[v]; e < normalized->offsets[v + 1]; ++e) {
      total += normalized->weights[e];
    }
    worst = std::max(worst, std::abs(total - 1));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(ReadDmat, ReadsTheArmsAsciiWeights) {
  DEFORM_REQUIRE_SHARED_FILE(mesh, "arm/arm_8311.obj");
  DEFORM_REQUIRE_SHARED_FILE(weights, "arm/arm_8311_weights.dmat");
  CheckSharedArmWeights(mesh, weights, 8311);
}

TEST(ReadDmat, ReadsTheArmsBinaryWeights) {
  DEFORM_REQUIRE_SHARED_FILE(mesh, "arm/arm_132946.obj");
  DEFORM_REQUIRE_SHARED_FILE(weights, "arm/arm_132946_weights.dmat");
  CheckSharedArmWeights(mesh, weights, 132946);
}

}  // namespace
}  // namespace deform
