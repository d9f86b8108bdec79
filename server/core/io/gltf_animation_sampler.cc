// Sampling glTF animations (the interpolation rules of the glTF 2.0 specification, section 3.11
// and Appendix C) into node transforms, bone transforms and poses.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/io/gltf_animation.h"

namespace deform {
namespace {

Eigen::Vector4d Element(const AnimationChannel& channel, std::size_t element) {
  const int n = channel.components();
  Eigen::Vector4d v = Eigen::Vector4d::Zero();
  for (int c = 0; c < n; ++c) v[c] = channel.values[element * static_cast<std::size_t>(n) + c];
  return v;
}

// Key k's value (the middle element of a cubic-spline key).
Eigen::Vector4d KeyValue(const AnimationChannel& channel, std::size_t k) {
  return Element(channel,
                 channel.interpolation == AnimationInterpolation::kCubicSpline ? 3 * k + 1 : k);
}

Eigen::Vector4d NormalizedRotation(const Eigen::Vector4d& q, const Eigen::Vector4d& fallback) {
  const double norm = q.norm();
  return norm > 1e-12 ? Eigen::Vector4d(q / norm) : Eigen::Vector4d(fallback / fallback.norm());
}

// glTF's x, y, z, w into Eigen's quaternion and back.
Eigen::Quaterniond ToQuaternion(const Eigen::Vector4d& xyzw) {
  return Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
}

}  // namespace

Eigen::Vector4d SampleChannel(const AnimationChannel& channel, double t) {
  const std::vector<double>& times = channel.times;
  const bool rotation = channel.path == AnimationPath::kRotation;
  const auto finish = [&](const Eigen::Vector4d& v, std::size_t near) {
    return rotation ? NormalizedRotation(v, KeyValue(channel, near)) : v;
  };
  const std::size_t last = times.size() - 1;
  if (!(t > times.front())) return finish(KeyValue(channel, 0), 0);
  if (!(t < times.back())) return finish(KeyValue(channel, last), last);
  // The key interval [times[k], times[k + 1]) holding t.
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin() - 1);
  const double interval = times[k + 1] - times[k];
  const double u = (t - times[k]) / interval;
  switch (channel.interpolation) {
    case AnimationInterpolation::kStep:
      return finish(KeyValue(channel, k), k);
    case AnimationInterpolation::kLinear: {
      const Eigen::Vector4d a = KeyValue(channel, k), b = KeyValue(channel, k + 1);
      if (!rotation) return (1 - u) * a + u * b;
      // The specification's slerp: the shortest path between the two unit quaternions.
      const Eigen::Quaterniond qa = ToQuaternion(a).normalized(), qb = ToQuaternion(b).normalized();
      const Eigen::Quaterniond q = qa.slerp(u, qb).normalized();
      return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
    }
    case AnimationInterpolation::kCubicSpline: {
      const Eigen::Vector4d p0 = Element(channel, 3 * k + 1);
      const Eigen::Vector4d m0 = interval * Element(channel, 3 * k + 2);  // out-tangent of k
      const Eigen::Vector4d p1 = Element(channel, 3 * (k + 1) + 1);
      const Eigen::Vector4d m1 = interval * Element(channel, 3 * (k + 1));  // in-tangent of k + 1
      const double u2 = u * u, u3 = u2 * u;
      const Eigen::Vector4d v = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 +
                                (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
      return finish(v, u < 0.5 ? k : k + 1);
    }
  }
  return KeyValue(channel, k);
}

std::vector<Eigen::Matrix4d> SampleLocalTransforms(const GltfAnimations& animations, int animation,
                                                   double t) {
  std::vector<Eigen::Matrix4d> local = animations.rest_matrix;
  std::vector<NodeTrs> trs = animations.rest_trs;
  std::vector<bool> animated(local.size(), false);
  for (const AnimationChannel& channel :
       animations.animations[static_cast<std::size_t>(animation)].channels) {
    const auto node = static_cast<std::size_t>(channel.node);
    const Eigen::Vector4d v = SampleChannel(channel, t);
    switch (channel.path) {
      case AnimationPath::kTranslation:
        trs[node].translation = v.head<3>();
        break;
      case AnimationPath::kRotation:
        trs[node].rotation = ToQuaternion(v);
        break;
      case AnimationPath::kScale:
        trs[node].scale = v.head<3>();
        break;
    }
    animated[node] = true;
  }
  for (std::size_t n = 0; n < local.size(); ++n) {
    if (animated[n]) local[n] = trs[n].Matrix();
  }
  return local;
}

std::vector<Eigen::Matrix4d> SampleWorldTransforms(const GltfAnimations& animations, int animation,
                                                   double t) {
  std::vector<Eigen::Matrix4d> world = SampleLocalTransforms(animations, animation, t);
  for (const int n : animations.parents_first) {
    const int parent = animations.node_parent[static_cast<std::size_t>(n)];
    if (parent >= 0) {
      world[static_cast<std::size_t>(n)] =
          world[static_cast<std::size_t>(parent)] * world[static_cast<std::size_t>(n)];
    }
  }
  return world;
}

std::vector<RigidTransform> SampleBoneTransforms(const GltfAnimations& animations, int animation,
                                                 double t) {
  const std::vector<Eigen::Matrix4d> world = SampleWorldTransforms(animations, animation, t);
  std::vector<RigidTransform> bones;
  bones.reserve(animations.bone_head_node.size());
  for (std::size_t k = 0; k < animations.bone_head_node.size(); ++k) {
    const Eigen::Matrix4d joint_matrix =
        world[static_cast<std::size_t>(animations.bone_head_node[k])] *
        animations.bone_inverse_bind[k];
    bones.push_back(RigidTransformFromMatrix(joint_matrix));
  }
  return bones;
}

StatusOr<BoneTransformPose> SamplePose(const GltfAnimations& animations, int animation, double t) {
  return PoseFromBoneTransforms(animations.joint_rest, animations.bones,
                                SampleBoneTransforms(animations, animation, t));
}

StatusOr<std::vector<double>> AnimationFrameTimes(const GltfAnimation& animation, double fps,
                                                  std::size_t max_frames) {
  if (!std::isfinite(fps) || !(fps > 0)) {
    return Status::InvalidArgument("frames a second must be positive and finite (got " +
                                   std::to_string(fps) + ")");
  }
  const double duration = animation.end - animation.start;
  // Frames start + k / fps while before the end, then the end itself.
  const double steps = std::ceil(duration * fps - 1e-9);
  if (!(steps + 1 <= static_cast<double>(max_frames))) {
    return Status::ResourceExhausted("animation '" + animation.name + "' (" +
                                     std::to_string(duration) + " s) at " + std::to_string(fps) +
                                     " frames a second is more than " + std::to_string(max_frames) +
                                     " frames");
  }
  std::vector<double> times;
  const auto count = static_cast<std::size_t>(std::max(steps, 0.0)) + 1;
  times.reserve(count);
  for (std::size_t k = 0; k + 1 < count; ++k) {
    times.push_back(animation.start + static_cast<double>(k) / fps);
  }
  times.push_back(animation.end);
  return times;
}

}  // namespace deform
