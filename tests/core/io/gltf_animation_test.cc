// The glTF animation reader and sampler: a four-joint chain written here (a static, weightless top
// joint "root" above hip -> knee -> ankle), animated in every interpolation mode; sampled values
// against values computed by hand, poses against the file's own skinning, and every malformed
// animation refused with a message naming the problem.
#include "core/io/gltf_animation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/geometry/pose.h"
#include "core/io/rig_import.h"
#include "tests/core/io/gltf_test_util.h"

namespace deform {
namespace {

using ::testing::HasSubstr;

// One sampler's keys: times and flat output values (x, y, z[, w] per element).
struct Keys {
  std::vector<float> times;
  std::vector<float> values;
  std::string interpolation = "LINEAR";
};

class AnimatedChain {
 public:
  AnimatedChain() {
    const gltf_test::TestRig tube = gltf_test::Tube();
    for (int v = 0; v < tube.mesh.num_vertices(); ++v) {
      const double y = tube.mesh.vertices(v, 1);
      data_.positions.insert(data_.positions.end(), {static_cast<float>(tube.mesh.vertices(v, 0)),
                                                     static_cast<float>(y + 1),
                                                     static_cast<float>(tube.mesh.vertices(v, 2))});
      const float w = static_cast<float>(gltf_test::LowerBoneWeight(y));
      data_.joints.insert(data_.joints.end(), {1, 2, 0, 0});
      data_.weights.insert(data_.weights.end(), {w, 1 - w, 0, 0});
    }
    for (Eigen::Index t = 0; t < tube.mesh.triangles.rows(); ++t) {
      for (int c = 0; c < 3; ++c)
        data_.indices.push_back(static_cast<std::uint32_t>(tube.mesh.triangles(t, c)));
    }
    builder_ = gltf_test::ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}}, {data_});
    const std::vector<std::string> names = {"root", "hip", "knee", "ankle"};
    for (std::size_t j = 0; j < names.size(); ++j) builder_.doc()["nodes"][j]["name"] = names[j];
    builder_.doc()["animations"] = nlohmann::json::array();
  }

  // Starts a new animation named `name`.
  void Animation(const std::string& name) {
    builder_.doc()["animations"].push_back({{"name", name},
                                            {"channels", nlohmann::json::array()},
                                            {"samplers", nlohmann::json::array()}});
  }
  // Adds a channel on `node`'s `path` with its own sampler over `keys` to the last animation.
  void Channel(int node, const std::string& path, const Keys& keys) {
    nlohmann::json& animation = builder_.doc()["animations"].back();
    const int components = path == "rotation" ? 4 : 3;
    const int input = builder_.AddAccessor(gltf_test::Bytes(keys.times), gltf_test::kFloat,
                                           "SCALAR", static_cast<int>(keys.times.size()));
    const int output = builder_.AddAccessor(gltf_test::Bytes(keys.values), gltf_test::kFloat,
                                            components == 4 ? "VEC4" : "VEC3",
                                            static_cast<int>(keys.values.size()) / components);
    animation["samplers"].push_back(
        {{"input", input}, {"output", output}, {"interpolation", keys.interpolation}});
    animation["channels"].push_back({{"sampler", animation["samplers"].size() - 1},
                                     {"target", {{"node", node}, {"path", path}}}});
  }
  nlohmann::json& doc() { return builder_.doc(); }
  const gltf_test::PrimitiveData& data() const { return data_; }

  // The rig and its animations, both read from the file.
  void Read() {
    bytes_ = builder_.ToGlb();
    auto rig = ReadGltf(bytes_);
    ASSERT_TRUE(rig.ok()) << rig.status().ToString();
    rig_ = std::move(*rig);
    auto animations = ReadGltfAnimations(bytes_, rig_.skeleton);
    ASSERT_TRUE(animations.ok()) << animations.status().ToString();
    animations_ = std::move(*animations);
  }
  // The reader's refusal of the file.
  Status Refusal() {
    bytes_ = builder_.ToGlb();
    auto rig = ReadGltf(bytes_);
    EXPECT_TRUE(rig.ok()) << rig.status().ToString();
    if (!rig.ok()) return rig.status();
    auto animations = ReadGltfAnimations(bytes_, rig->skeleton);
    EXPECT_FALSE(animations.ok());
    return animations.ok() ? Status::Ok() : animations.status();
  }
  const RigImport& rig() const { return rig_; }
  const GltfAnimations& animations() const { return animations_; }

 private:
  gltf_test::PrimitiveData data_;
  gltf_test::GltfBuilder builder_;
  std::string bytes_;
  RigImport rig_;
  GltfAnimations animations_;
};

const double kHalfTurn = std::sin(M_PI / 8);  // sin(22.5 degrees)
const double kHalfTurnW = std::cos(M_PI / 8);

const AnimationChannel& ChannelOn(const GltfAnimation& animation, int node, AnimationPath path) {
  for (const AnimationChannel& channel : animation.channels) {
    if (channel.node == node && channel.path == path) return channel;
  }
  ADD_FAILURE() << "no channel on node " << node;
  return animation.channels.front();
}

void ExpectNear(const Eigen::Vector4d& got, const Eigen::Vector4d& expected, int components) {
  for (int c = 0; c < components; ++c) EXPECT_NEAR(got[c], expected[c], 1e-7) << "component " << c;
}

TEST(GltfAnimation, LinearLerpsTranslationsAndSlerpsRotations) {
  AnimatedChain chain;
  chain.Animation("walk");
  chain.Channel(1, "translation", {{0, 2}, {0, 1, 0, 2, 1, 4}});
  // The identity to 90 degrees about x: the midpoint is 45 degrees about x.
  chain.Channel(
      2, "rotation",
      {{0, 2},
       {0, 0, 0, 1, static_cast<float>(std::sqrt(0.5)), 0, 0, static_cast<float>(std::sqrt(0.5))}});
  chain.Read();
  ASSERT_EQ(chain.animations().animations.size(), 1u);
  const GltfAnimation& walk = chain.animations().animations[0];
  EXPECT_EQ(walk.name, "walk");
  EXPECT_DOUBLE_EQ(walk.start, 0);
  EXPECT_DOUBLE_EQ(walk.end, 2);
  const AnimationChannel& move = ChannelOn(walk, 1, AnimationPath::kTranslation);
  ExpectNear(SampleChannel(move, 0.5), {0.5, 1, 1, 0}, 3);
  ExpectNear(SampleChannel(move, -3), {0, 1, 0, 0}, 3);  // before the first key: the first
  ExpectNear(SampleChannel(move, 7), {2, 1, 4, 0}, 3);   // after the last: the last
  const AnimationChannel& bend = ChannelOn(walk, 2, AnimationPath::kRotation);
  ExpectNear(SampleChannel(bend, 1), {kHalfTurn, 0, 0, kHalfTurnW}, 4);
  // A quarter of the way: 22.5 degrees (slerp, not nlerp, which gives about 23.8).
  ExpectNear(SampleChannel(bend, 0.5), {std::sin(M_PI / 16), 0, 0, std::cos(M_PI / 16)}, 4);
  // Nodes without a channel keep their rest transforms; the knee's local transform is its rest
  // translation with the sampled rotation.
  const std::vector<Eigen::Matrix4d> local = SampleLocalTransforms(chain.animations(), 0, 1);
  EXPECT_TRUE(local[0].isApprox(Eigen::Matrix4d::Identity()));
  EXPECT_TRUE(local[3].isApprox(gltf_test::NodeMatrix({0, 1, 0}, Eigen::Quaterniond::Identity())));
  EXPECT_TRUE(local[2].isApprox(gltf_test::NodeMatrix(
      {0, 1, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitX())))));
}

TEST(GltfAnimation, SlerpTakesTheShortestPath) {
  AnimatedChain chain;
  chain.Animation("turn");
  // The identity to -q of 90 degrees about z (the same rotation, the far hemisphere).
  chain.Channel(2, "rotation",
                {{0, 1},
                 {0, 0, 0, 1, 0, 0, static_cast<float>(-std::sqrt(0.5)),
                  static_cast<float>(-std::sqrt(0.5))}});
  chain.Read();
  const Eigen::Vector4d mid = SampleChannel(chain.animations().animations[0].channels[0], 0.5);
  const Eigen::Quaterniond q(mid[3], mid[0], mid[1], mid[2]);
  EXPECT_NEAR(
      q.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()))),
      0, 1e-7);
}

TEST(GltfAnimation, StepHoldsEachKeyUntilTheNext) {
  AnimatedChain chain;
  chain.Animation("jump");
  chain.Channel(1, "translation", {{0, 1, 2}, {0, 1, 0, 5, 1, 0, 5, 3, 0}, "STEP"});
  chain.Read();
  const AnimationChannel& jump = chain.animations().animations[0].channels[0];
  EXPECT_EQ(jump.interpolation, AnimationInterpolation::kStep);
  ExpectNear(SampleChannel(jump, 0.99), {0, 1, 0, 0}, 3);
  ExpectNear(SampleChannel(jump, 1), {5, 1, 0, 0}, 3);
  ExpectNear(SampleChannel(jump, 1.5), {5, 1, 0, 0}, 3);
  ExpectNear(SampleChannel(jump, 2), {5, 3, 0, 0}, 3);
}

TEST(GltfAnimation, CubicSplineFollowsTheSpecsHermiteFormula) {
  AnimatedChain chain;
  chain.Animation("swing");
  // Keys at 0 and 2: (in-tangent, value, out-tangent) each. At t = 1 (u = 1/2, interval 2):
  // p = 1/2 v0 + 1/8 * 2 b0 + 1/2 v1 - 1/8 * 2 a1
  //   = (0, 0.5, 0) + (0.25, 0, 0) + (0, 0.5, 1) - (0, 0, 0.25) = (0.25, 1, 0.75).
  chain.Channel(1, "translation",
                {{0, 2}, {9, 9, 9, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 9, 9, 9}, "CUBICSPLINE"});
  // Rotations: the identity to 90 degrees about z, zero tangents: the Hermite midpoint is the
  // mean of the two, normalized: 45 degrees about z.
  const float h = static_cast<float>(std::sqrt(0.5));
  chain.Channel(2, "rotation",
                {{0, 2},
                 {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, h, h, 0, 0, 0, 0},
                 "CUBICSPLINE"});
  chain.Read();
  const GltfAnimation& swing = chain.animations().animations[0];
  const AnimationChannel& move = ChannelOn(swing, 1, AnimationPath::kTranslation);
  ExpectNear(SampleChannel(move, 1), {0.25, 1, 0.75, 0}, 3);
  // At u = 1/4: h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = -3/64, tangents times 2.
  ExpectNear(SampleChannel(move, 0.5),
             {2 * 9.0 / 64, 27.0 / 32 + 5.0 / 32, 5.0 / 32 * 2 - 2 * 3.0 / 64, 0}, 3);
  ExpectNear(SampleChannel(move, 2), {0, 1, 2, 0}, 3);  // the last value, not a tangent
  ExpectNear(SampleChannel(move, -1), {0, 1, 0, 0}, 3);
  const AnimationChannel& turn = ChannelOn(swing, 2, AnimationPath::kRotation);
  ExpectNear(SampleChannel(turn, 1), {0, 0, kHalfTurn, kHalfTurnW}, 4);
}

TEST(GltfAnimation, AnimationsAreFoundByNameOrIndex) {
  AnimatedChain chain;
  chain.Animation("idle");
  chain.Channel(1, "translation", {{0, 1}, {0, 1, 0, 0, 1, 0}});
  chain.Animation("");
  chain.Channel(1, "translation", {{0.5, 3}, {0, 1, 0, 0, 2, 0}});
  chain.Read();
  EXPECT_EQ(*FindAnimation(chain.animations(), "idle"), 0);
  EXPECT_EQ(*FindAnimation(chain.animations(), "1"), 1);
  EXPECT_EQ(*FindAnimation(chain.animations(), "animation1"), 1);  // the unnamed one's name
  EXPECT_DOUBLE_EQ(chain.animations().animations[1].start, 0.5);
  const auto missing = FindAnimation(chain.animations(), "run");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("'idle', 'animation1'"));
  EXPECT_FALSE(FindAnimation(chain.animations(), "2").ok());
}

TEST(GltfAnimation, FrameTimesCoverTheDurationAndItsEnd) {
  GltfAnimation animation;
  animation.start = 0.5;
  animation.end = 1.5;
  const auto times = AnimationFrameTimes(animation, 4);
  ASSERT_TRUE(times.ok());
  EXPECT_EQ(*times, (std::vector<double>{0.5, 0.75, 1.0, 1.25, 1.5}));
  animation.end = 1.6;
  EXPECT_EQ(AnimationFrameTimes(animation, 4)->back(), 1.6);
  EXPECT_EQ(AnimationFrameTimes(animation, 4)->size(), 6u);
  EXPECT_FALSE(AnimationFrameTimes(animation, 0).ok());
  EXPECT_FALSE(AnimationFrameTimes(animation, 1e9, 1000).ok());
}

// Linear blend skinning of the rig's weights under `pose`, per file vertex.
Positions LbsOfFile(const RigImport& rig, const Pose& pose) {
  std::vector<RigidTransform> transforms;
  ForwardKinematics(rig.skeleton, pose, &transforms);
  const Positions& rest = rig.mesh.vertices;
  Positions lbs(static_cast<Eigen::Index>(rig.file_vertex_to_mesh.size()), 3);
  for (std::size_t v = 0; v < rig.file_vertex_to_mesh.size(); ++v) {
    const int m = rig.file_vertex_to_mesh[v];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int e = rig.weights.offsets[m]; e < rig.weights.offsets[m + 1]; ++e) {
      const RigidTransform& t = transforms[static_cast<std::size_t>(rig.weights.bones[e])];
      sum += rig.weights.weights[e] * (t.rotation * rest.row(m).transpose() + t.translation);
    }
    lbs.row(static_cast<Eigen::Index>(v)) = sum.transpose();
  }
  return lbs;
}

TEST(GltfAnimation, PlayedFramesMatchTheFilesOwnSkinningWithRootMotion) {
  // The hip walks forward and turns, the knee bends; the top joint stays at rest (root motion
  // taken from the hip). Keys at 0, 1, 2 seconds, LINEAR.
  const std::vector<Eigen::Vector3d> hip_at = {{0, 1, 0}, {0.4, 1.1, 0.5}, {1, 1, 1.5}};
  const std::vector<Eigen::Quaterniond> hip_turn = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, 0.5).normalized())),
      Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()))};
  const std::vector<Eigen::Quaterniond> knee_bend = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitX())),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))};
  AnimatedChain chain;
  chain.Animation("walk");
  Keys translation{{0, 1, 2}, {}}, hip{{0, 1, 2}, {}}, knee{{0, 1, 2}, {}};
  for (int k = 0; k < 3; ++k) {
    for (int c = 0; c < 3; ++c) translation.values.push_back(static_cast<float>(hip_at[k][c]));
    for (const auto& [q, keys] : {std::pair{hip_turn[k], &hip}, std::pair{knee_bend[k], &knee}}) {
      keys->values.insert(keys->values.end(),
                          {static_cast<float>(q.x()), static_cast<float>(q.y()),
                           static_cast<float>(q.z()), static_cast<float>(q.w())});
    }
  }
  chain.Channel(1, "translation", translation);
  chain.Channel(1, "rotation", hip);
  chain.Channel(2, "rotation", knee);
  chain.Read();
  const RigImport& rig = chain.rig();
  const Positions& rest = rig.mesh.vertices;
  const double diagonal = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  const auto times = AnimationFrameTimes(chain.animations().animations[0], 4);
  ASSERT_TRUE(times.ok());
  ASSERT_EQ(times->size(), 9u);
  for (const double t : *times) {
    // The file's own skinning at t, from the keys above: lerp and slerp between the two keys
    // around t (as the keys were written, in float).
    const int k = std::min(static_cast<int>(t), 1);
    const double u = t - k;
    const auto as_float = [](const Eigen::Quaterniond& q) {
      return Eigen::Quaterniond(static_cast<float>(q.w()), static_cast<float>(q.x()),
                                static_cast<float>(q.y()), static_cast<float>(q.z()));
    };
    const auto lerp = [&](const std::vector<Eigen::Vector3d>& at) {
      return Eigen::Vector3d((1 - u) * at[k].cast<float>().cast<double>() +
                             u * at[k + 1].cast<float>().cast<double>());
    };
    const auto slerp = [&](const std::vector<Eigen::Quaterniond>& q) {
      return as_float(q[k]).normalized().slerp(u, as_float(q[k + 1]).normalized());
    };
    const std::vector<Eigen::Matrix4d> local = {
        Eigen::Matrix4d::Identity(), gltf_test::NodeMatrix(lerp(hip_at), slerp(hip_turn)),
        gltf_test::NodeMatrix({0, 1, 0}, slerp(knee_bend)),
        gltf_test::NodeMatrix({0, 1, 0}, Eigen::Quaterniond::Identity())};
    const std::vector<Eigen::Vector3d> rest_at = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}};
    std::vector<Eigen::Matrix4d> joint_matrix(4);
    Eigen::Matrix4d world = Eigen::Matrix4d::Identity();
    for (int j = 0; j < 4; ++j) {
      world = world * local[j];
      joint_matrix[j] = world * gltf_test::NodeMatrix(-rest_at[j], Eigen::Quaterniond::Identity());
    }
    const Positions reference = gltf_test::SkinAsGltf(chain.data(), joint_matrix);

    const auto pose = SamplePose(chain.animations(), 0, t);
    ASSERT_TRUE(pose.ok()) << pose.status().ToString();
    if (t > 0) {
      EXPECT_EQ(pose->root_taken_from_bone, 1) << "t " << t;
    }
    const Positions lbs = LbsOfFile(rig, pose->pose);
    double worst = 0;
    for (Eigen::Index v = 0; v < lbs.rows(); ++v) {
      worst = std::max(worst, (lbs.row(v) - reference.row(v)).norm());
    }
    EXPECT_LT(worst, 1e-6 * diagonal) << "t " << t;
  }
}

// Refusals: each malformed animation is INVALID_ARGUMENT (or RESOURCE_EXHAUSTED) naming it.
class GltfAnimationRefusal : public ::testing::Test {
 protected:
  GltfAnimationRefusal() {
    chain_.Animation("bad");
    chain_.Channel(1, "translation", {{0, 1}, {0, 1, 0, 1, 1, 0}});
  }
  nlohmann::json& Sampler() { return chain_.doc()["animations"][0]["samplers"][0]; }
  nlohmann::json& Channel() { return chain_.doc()["animations"][0]["channels"][0]; }
  nlohmann::json& Accessor(int index) { return chain_.doc()["accessors"][index]; }
  void ExpectRefused(const std::string& part) {
    const Status status = chain_.Refusal();
    EXPECT_FALSE(status.ok());
    EXPECT_THAT(status.message(), HasSubstr(part));
    EXPECT_THAT(status.message(), HasSubstr("animation 0 'bad'"));
  }
  AnimatedChain chain_;
};

TEST_F(GltfAnimationRefusal, TimesThatDoNotIncrease) {
  chain_.Channel(2, "scale", {{0, 1, 1}, {1, 1, 1, 1, 1, 1, 1, 1, 1}});
  ExpectRefused("times are not strictly increasing at key 2");
}

TEST_F(GltfAnimationRefusal, NegativeTimes) {
  chain_.Channel(2, "scale", {{-1, 1}, {1, 1, 1, 1, 1, 1}});
  ExpectRefused("is negative");
}

TEST_F(GltfAnimationRefusal, OutputCountThatDoesNotMatchTheTimes) {
  chain_.Channel(2, "scale", {{0, 1, 2}, {1, 1, 1, 1, 1, 1}});
  ExpectRefused("has 2 elements; expected 3 (one per key)");
}

TEST_F(GltfAnimationRefusal, CubicSplineWithoutTangents) {
  chain_.Channel(2, "scale", {{0, 1}, {1, 1, 1, 1, 1, 1}, "CUBICSPLINE"});
  ExpectRefused("expected 6 (in-tangent, value and out-tangent per key)");
}

TEST_F(GltfAnimationRefusal, CubicSplineWithOneKey) {
  chain_.Channel(2, "scale", {{0}, {0, 0, 0, 1, 1, 1, 0, 0, 0}, "CUBICSPLINE"});
  ExpectRefused("it needs at least 2");
}

TEST_F(GltfAnimationRefusal, RotationsThatAreNotVec4) {
  chain_.Channel(2, "rotation", {{0, 1}, {0, 0, 0, 1, 0, 0, 0, 1}});
  const int output = chain_.doc()["animations"][0]["samplers"][1]["output"];
  Accessor(output)["type"] = "VEC3";
  ExpectRefused("has type VEC3; expected VEC4");
}

TEST_F(GltfAnimationRefusal, TimesThatAreNotFloats) {
  Accessor(Sampler()["input"].get<int>())["componentType"] = gltf_test::kUnsignedShort;
  ExpectRefused("input (times)");
}

TEST_F(GltfAnimationRefusal, ZeroQuaternion) {
  chain_.Channel(2, "rotation", {{0, 1}, {0, 0, 0, 1, 0, 0, 0, 0}});
  ExpectRefused("the rotation of key 1 is a zero quaternion");
}

TEST_F(GltfAnimationRefusal, TargetNodeOutOfRange) {
  Channel()["target"]["node"] = 99;
  ExpectRefused("targets node 99, which does not exist");
}

TEST_F(GltfAnimationRefusal, SamplerOutOfRange) {
  Channel()["sampler"] = 5;
  ExpectRefused("refers to sampler 5, which does not exist");
}

TEST_F(GltfAnimationRefusal, AccessorOutOfRange) {
  Sampler()["output"] = 999;
  ExpectRefused("accessor 999");
}

TEST_F(GltfAnimationRefusal, UnknownInterpolation) {
  Sampler()["interpolation"] = "BEZIER";
  ExpectRefused("interpolation 'BEZIER'");
}

TEST_F(GltfAnimationRefusal, UnknownPath) {
  Channel()["target"]["path"] = "colour";
  ExpectRefused("path 'colour'");
}

TEST_F(GltfAnimationRefusal, TwoChannelsOnOneTarget) {
  chain_.Channel(1, "translation", {{0, 1}, {0, 1, 0, 1, 1, 0}});
  ExpectRefused("which an earlier channel of the animation targets");
}

TEST_F(GltfAnimationRefusal, AnimatedNodeWithAMatrix) {
  chain_.doc()["nodes"][1].erase("translation");
  chain_.doc()["nodes"][1]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1};
  ExpectRefused("which has a matrix");
}

TEST_F(GltfAnimationRefusal, AnimationWithoutChannels) {
  chain_.doc()["animations"][0]["channels"] = nlohmann::json::array();
  ExpectRefused("has no channels");
}

}  // namespace
}  // namespace deform
