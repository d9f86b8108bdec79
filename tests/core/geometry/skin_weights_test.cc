#include "core/geometry/skin_weights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace deform {
namespace {

SkinWeights TwoVertices() {
  SkinWeights w;
  w.num_bones = 3;
  w.AddVertex({2, 0, 2}, {0.5, 1.0, 0.5});  // bone 2 twice: summed
  w.AddVertex({1}, {4.0});                  // one bone, not normalized
  return w;
}

TEST(SkinWeights, NormalizesSortsAndSumsRepeats) {
  auto normalized = NormalizeSkinWeights(TwoVertices(), 2, 3);
  ASSERT_TRUE(normalized.ok()) << normalized.status().ToString();
  ASSERT_EQ(normalized->offsets, (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(normalized->bones, (std::vector<int>{0, 2, 1}));
  EXPECT_DOUBLE_EQ(normalized->weights[0], 0.5);
  EXPECT_DOUBLE_EQ(normalized->weights[1], 0.5);
  EXPECT_DOUBLE_EQ(normalized->weights[2], 1.0);
}

TEST(SkinWeights, DropsNegligibleWeights) {
  SkinWeights w;
  w.num_bones = 2;
  w.AddVertex({0, 1}, {1.0, 1e-9});
  auto normalized = NormalizeSkinWeights(w, 1, 2);
  ASSERT_TRUE(normalized.ok());
  EXPECT_EQ(normalized->bones, (std::vector<int>{0}));
  EXPECT_DOUBLE_EQ(normalized->weights[0], 1.0);
}

TEST(SkinWeights, RefusesWhatNoRigCanMean) {
  auto expect_refused = [](const SkinWeights& w, int vertices, int bones, const char* needle) {
    auto result = NormalizeSkinWeights(w, vertices, bones);
    ASSERT_FALSE(result.ok()) << needle;
    EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(result.status().message().find(needle), std::string::npos)
        << result.status().message();
  };
  expect_refused(TwoVertices(), 3, 3, "the mesh has 3");
  expect_refused(TwoVertices(), 2, 4, "the skeleton has 4");
  SkinWeights bad_bone;
  bad_bone.num_bones = 2;
  bad_bone.AddVertex({5}, {1});
  expect_refused(bad_bone, 1, 2, "no such bone");
  SkinWeights negative;
  negative.num_bones = 2;
  negative.AddVertex({0, 1}, {1.5, -0.5});
  expect_refused(negative, 1, 2, "non-negative");
  SkinWeights nan;
  nan.num_bones = 1;
  nan.AddVertex({0}, {std::numeric_limits<double>::quiet_NaN()});
  expect_refused(nan, 1, 1, "finite");
  SkinWeights empty_vertex;
  empty_vertex.num_bones = 1;
  empty_vertex.AddVertex({}, {});
  expect_refused(empty_vertex, 1, 1, "at least one bone");
  SkinWeights malformed = TwoVertices();
  malformed.offsets[1] = 7;
  expect_refused(malformed, 2, 3, "offsets");
}

}  // namespace
}  // namespace deform
