#include "core/model/general_rows.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tests/core/model/random_row_system.h"

namespace deform {
namespace {

// A system of n vertex columns and n + m rows: row i reads 1 + i % 21 consecutive vertices from
// i (mod n), so rows of every packed length and longer ones; the node rows read 40 vertices each.
// Bone weights: vertices [0, n / 4) wholly bone 0's, then runs blended between bones (1, 2),
// (2, 1) (the same bones, the other first), (3, 1, 2) and wholly bone 3's. Bone 2's quaternion is
// stored with a negative w, so its sign against bone 1's and bone 3's must be aligned.
struct Fixture {
  static constexpr int n = 203;  // groups of sizes that are not multiples of 8
  static constexpr int m = 2;
  LaplacianSystem system;
  BoneWeights weights;
  Eigen::VectorXd w2 = Eigen::VectorXd::Zero(n);
  std::vector<RigidTransform> bones;
  std::vector<Eigen::Matrix3d> rotations;

  Fixture() {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> value(-1, 1);
    system = test_support::RandomRowSystem(
        n, m, 3, [](int i) { return i < n ? 1 + i % 21 : 40; }, &random);
    weights.num_bones = 4;
    weights.offsets.push_back(0);
    for (int j = 0; j < n; ++j) {
      const double a = 0.5 + 0.4 * value(random);  // in (0.1, 0.9)
      if (j < n / 4) {
        Add({0}, {1.0});
      } else if (j < n / 2) {
        Add({1, 2}, {std::max(a, 1 - a), std::min(a, 1 - a)});
      } else if (j < 5 * n / 8) {
        Add({2, 1}, {std::max(a, 1 - a), std::min(a, 1 - a)});
      } else if (j < 7 * n / 8) {
        Add({3, 1, 2}, {0.5, 0.3, 0.2});
      } else {
        Add({3}, {1.0});
      }
      w2[j] = 0.5 + value(random) * value(random);
    }
    // Every third vertex an anchor that follows the vertex's own bones.
    system.anchor_weight = 3.0;
    system.anchor_offsets.push_back(0);
    for (int j = 0; j < n; j += 3) {
      system.anchors.push_back(j);
      for (int p = weights.offsets[j]; p < weights.offsets[j + 1]; ++p) {
        system.anchor_bones.push_back(weights.bones[p]);
        system.anchor_weights.push_back(weights.weights[p]);
      }
      system.anchor_offsets.push_back(static_cast<int>(system.anchor_bones.size()));
    }
    system.anchor_rest = Positions::NullaryExpr(static_cast<int>(system.anchors.size()), 3,
                                                [&] { return value(random); });
    for (int b = 0; b < 4; ++b) {
      RigidTransform bone;
      bone.translation = Eigen::Vector3d(b, -1.0, 0.5 * b);
      bone.rotation = Eigen::AngleAxisd(0.3 + b, Eigen::Vector3d(1, b, 2).normalized());
      if (b == 2) bone.rotation.coeffs() = -bone.rotation.coeffs();
      bones.push_back(bone);
      rotations.push_back(bone.rotation.toRotationMatrix());
    }
  }

  void Add(std::vector<int> b, std::vector<double> w) {
    weights.bones.insert(weights.bones.end(), b.begin(), b.end());
    weights.weights.insert(weights.weights.end(), w.begin(), w.end());
    weights.offsets.push_back(static_cast<int>(weights.bones.size()));
  }

  // L'^T r with r_j = w_j^2 T_j delta_j, T_j the normalized blend of vertex j's quaternions with
  // signs aligned to its first bone's, every row summed in full.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Expected() const {
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> r(n, 3);
    for (int j = 0; j < n; ++j) {
      const Eigen::Quaterniond& first = bones[weights.bones[weights.offsets[j]]].rotation;
      Eigen::Vector4d q = Eigen::Vector4d::Zero();
      for (int p = weights.offsets[j]; p < weights.offsets[j + 1]; ++p) {
        const Eigen::Quaterniond& qk = bones[weights.bones[p]].rotation;
        q += (first.dot(qk) < 0 ? -1.0 : 1.0) * weights.weights[p] * qk.coeffs();
      }
      const Eigen::Quaterniond blend = Eigen::Quaterniond(q).normalized();
      r.row(j) = w2[j] * (blend * Eigen::Vector3d(system.rest_deltas.row(j))).transpose();
    }
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> product(n + m, 3);
    MultiplyLaplacianTranspose(system, r.data(), product.data());
    return product;
  }
};

class GeneralRowsTest : public testing::TestWithParam<SolveKernel> {};

// The anchors' targets added to their rows equal anchor_weight^2 sum_e w_e (R_e rest + t_e), for
// every kernel and split into parts.
TEST_P(GeneralRowsTest, AnchorTargetsAreAddedToTheirRows) {
  if (!SolveKernelAvailable(GetParam())) GTEST_SKIP() << "this CPU lacks the instruction set";
  const Fixture f;
  const GeneralRowsPlan plan =
      GeneralRowsPlan::Build(f.system, RigidRows::Find(f.system, f.weights), f.weights, GetParam());
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> base(Fixture::n + Fixture::m, 3);
  base.setRandom();
  auto expected = base;
  for (int a = 0; a < static_cast<int>(f.system.anchors.size()); ++a) {
    Eigen::Vector3d target = Eigen::Vector3d::Zero();
    for (int e = f.system.anchor_offsets[a]; e < f.system.anchor_offsets[a + 1]; ++e) {
      const RigidTransform& bone = f.bones[f.system.anchor_bones[e]];
      target += f.system.anchor_weights[e] *
                bone.Apply(Eigen::Vector3d(f.system.anchor_rest.row(a).transpose()));
    }
    expected.row(f.system.anchors[a]) += 9.0 * target.transpose();
  }
  for (const int parts : {1, 2, 3}) {
    auto added = base;
    for (int part = 0; part < parts; ++part) {
      plan.AddAnchorTargets(f.rotations.data(), f.bones, added.data(), part, parts);
    }
    EXPECT_LT((added - expected).norm(), 1e-14 * expected.norm()) << parts << " parts";
  }
  EXPECT_GT((expected - base).norm(), 1.0);
}

// The plan's product equals the full product to round-off, for every kernel this CPU runs and
// split into parts as a parallel assembly splits it.
TEST_P(GeneralRowsTest, TheProductEqualsTheFullProductOfTheNormalizedBlend) {
  if (!SolveKernelAvailable(GetParam())) GTEST_SKIP() << "this CPU lacks the instruction set";
  const Fixture f;
  const RigidRows rigid = RigidRows::Find(f.system, f.weights);
  const std::vector<double> sums = RigidRowSums(f.system, rigid, f.w2);
  const GeneralRowsPlan plan = GeneralRowsPlan::Build(f.system, rigid, f.weights, GetParam());
  ASSERT_EQ(plan.slot_count() % GeneralRowsPlan::kSlotBlock, 0);
  const std::vector<double> slot_weights = plan.SlotWeights(f.w2);
  std::vector<double> quaternions(4 * static_cast<std::size_t>(plan.quaternion_count()));
  plan.SignQuaternions(f.bones, quaternions.data());
  const auto expected = f.Expected();
  for (const int parts : {1, 2, 3}) {
    std::vector<double> rotated(plan.rotated_size(), -1e300);
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> product(Fixture::n + Fixture::m, 3);
    product.setConstant(std::numeric_limits<double>::quiet_NaN());
    for (int part = 0; part < parts; ++part) {
      plan.Rotate(quaternions.data(), slot_weights.data(), rotated.data(), part, parts);
    }
    for (int part = parts - 1; part >= 0; --part) {
      plan.Multiply(f.rotations.data(), sums.data(), rotated.data(), product.data(), part, parts);
    }
    ASSERT_TRUE(product.allFinite()) << parts << " parts: a row not written";
    EXPECT_LT((product - expected).norm(), 1e-14 * expected.norm()) << parts << " parts";
  }
  EXPECT_GT(expected.norm(), 1.0);
}

// A batch's frames, their rotated deltas side by side and their general rows multiplied in one
// pass, each equal the frame's own product to round-off, for every kernel, frame count (chunks of
// eight frames and their remainders) and split into parts.
TEST_P(GeneralRowsTest, FramesSideBySideEqualEachFramesOwnProduct) {
  if (!SolveKernelAvailable(GetParam())) GTEST_SKIP() << "this CPU lacks the instruction set";
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  const Fixture f;
  const RigidRows rigid = RigidRows::Find(f.system, f.weights);
  const std::vector<double> sums = RigidRowSums(f.system, rigid, f.w2);
  const GeneralRowsPlan plan = GeneralRowsPlan::Build(f.system, rigid, f.weights, GetParam());
  const std::vector<double> slot_weights = plan.SlotWeights(f.w2);
  const int most = GeneralRowsPlan::kMaxFrames;
  // Frame k's bones: the fixture's, each turned by its own angle about its own axis.
  std::vector<std::vector<double>> quaternions(most);
  std::vector<std::vector<Eigen::Matrix3d>> rotations(most);
  std::vector<Rows> own(most, Rows(Fixture::n + Fixture::m, 3));
  std::vector<double> rotated(plan.rotated_size());
  for (int k = 0; k < most; ++k) {
    std::vector<RigidTransform> bones = f.bones;
    for (int b = 0; b < static_cast<int>(bones.size()); ++b) {
      bones[b].rotation =
          Eigen::AngleAxisd(0.1 * k + 0.05 * b, Eigen::Vector3d(b, 1, k).normalized()) *
          bones[b].rotation;
      rotations[k].push_back(bones[b].rotation.toRotationMatrix());
    }
    quaternions[k].resize(4 * static_cast<std::size_t>(plan.quaternion_count()));
    plan.SignQuaternions(bones, quaternions[k].data());
    plan.Rotate(quaternions[k].data(), slot_weights.data(), rotated.data(), 0, 1);
    plan.Multiply(rotations[k].data(), sums.data(), rotated.data(), own[k].data(), 0, 1);
  }
  for (const int frames : {1, 2, 3, 5, 8, 9, 13, most}) {
    for (const int parts : {1, 2, 3}) {
      std::vector<double> side_by_side(frames * plan.rotated_size(), -1e300);
      std::vector<Rows> products(frames, Rows(Fixture::n + Fixture::m, 3));
      std::vector<double*> outs;
      for (Rows& product : products) {
        product.setConstant(std::numeric_limits<double>::quiet_NaN());
        outs.push_back(product.data());
      }
      std::vector<const double*> frame_quaternions;
      for (int k = 0; k < frames; ++k) frame_quaternions.push_back(quaternions[k].data());
      for (int part = 0; part < parts; ++part) {
        plan.RotateFrames(frame_quaternions.data(), frames, slot_weights.data(),
                          side_by_side.data(), part, parts);
      }
      for (int part = parts - 1; part >= 0; --part) {
        plan.MultiplyGeneral(side_by_side.data(), frames, outs.data(), part, parts);
        for (int k = 0; k < frames; ++k) {
          plan.MultiplyRigid(rotations[k].data(), sums.data(), outs[k], part, parts);
        }
      }
      for (int k = 0; k < frames; ++k) {
        ASSERT_TRUE(products[k].allFinite()) << frames << " frames, " << parts << " parts";
        EXPECT_LT((products[k] - own[k]).norm(), 1e-14 * own[k].norm())
            << "frame " << k << " of " << frames << ", " << parts << " parts";
      }
    }
  }
  EXPECT_GT((own[1] - own[0]).norm(), 0.01 * own[0].norm()) << "the frames differ";
}

INSTANTIATE_TEST_SUITE_P(AllKernels, GeneralRowsTest,
                         testing::Values(SolveKernel::kBaseline, SolveKernel::kAvx2Fma,
                                         SolveKernel::kAvx512),
                         [](const testing::TestParamInfo<SolveKernel>& info) {
                           return std::string(SolveKernelName(info.param)) == "avx2+fma"
                                      ? std::string("avx2")
                                      : std::string(SolveKernelName(info.param));
                         });

// Slots only for the vertices general rows read, each group padded to whole blocks; the padding
// and the unread vertices carry no weight.
TEST(GeneralRows, SlotsAreTheReadVerticesInPaddedGroups) {
  const Fixture f;
  const RigidRows rigid = RigidRows::Find(f.system, f.weights);
  const GeneralRowsPlan plan = GeneralRowsPlan::Build(f.system, rigid, f.weights);
  int read = 0;
  for (int j = 0; j < Fixture::n; ++j) read += rigid.delta_read[j] ? 1 : 0;
  EXPECT_GE(plan.slot_count(), read);
  // Five bone lists at most, each padded by fewer than a block.
  EXPECT_LT(plan.slot_count(), read + 5 * GeneralRowsPlan::kSlotBlock);
  // One signed quaternion per bone of each list: {0}, {1, 2}, {2, 1}, {3, 1, 2}, {3}.
  EXPECT_EQ(plan.quaternion_count(), 1 + 2 + 2 + 3 + 1);
  const std::vector<double> slot_weights = plan.SlotWeights(f.w2);
  double sum = 0;
  for (const double w : slot_weights) sum += w;
  double expected = 0;
  for (int j = 0; j < Fixture::n; ++j) expected += rigid.delta_read[j] ? f.w2[j] : 0.0;
  EXPECT_NEAR(sum, expected, 1e-12);
  EXPECT_GT(plan.bytes(), 0u);
}

}  // namespace
}  // namespace deform
