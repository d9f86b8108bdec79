#include "gltf_animation_channels.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <set>
#include <string>
#include <utility>

#include "gltf_accessors.h"

namespace deform::gltf_internal {
namespace {

struct Target {
  bool used = false;  // false: a channel this reader ignores (morph weights, no node)
  AnimationPath path = AnimationPath::kTranslation;
};

StatusOr<Target> ReadTarget(const tinygltf::Model& model, const tinygltf::AnimationChannel& channel,
                            const std::string& what) {
  Target target;
  if (channel.target_path == "weights" || channel.target_node < 0) return target;
  if (channel.target_path == "translation") {
    target.path = AnimationPath::kTranslation;
  } else if (channel.target_path == "rotation") {
    target.path = AnimationPath::kRotation;
  } else if (channel.target_path == "scale") {
    target.path = AnimationPath::kScale;
  } else {
    return Status::InvalidArgument(what + " targets path '" + channel.target_path +
                                   "'; expected translation, rotation, scale or weights");
  }
  if (static_cast<std::size_t>(channel.target_node) >= model.nodes.size()) {
    return Status::InvalidArgument(what + " targets node " + std::to_string(channel.target_node) +
                                   ", which does not exist (the glTF has " +
                                   std::to_string(model.nodes.size()) + " nodes)");
  }
  if (!model.nodes[static_cast<std::size_t>(channel.target_node)].matrix.empty()) {
    return Status::InvalidArgument(what + " targets node " + std::to_string(channel.target_node) +
                                   ", which has a matrix (only TRS nodes may be animated)");
  }
  target.used = true;
  return target;
}

StatusOr<AnimationInterpolation> ReadInterpolation(const std::string& name,
                                                   const std::string& what) {
  if (name == "LINEAR" || name.empty()) return AnimationInterpolation::kLinear;
  if (name == "STEP") return AnimationInterpolation::kStep;
  if (name == "CUBICSPLINE") return AnimationInterpolation::kCubicSpline;
  return Status::InvalidArgument(what + " has interpolation '" + name +
                                 "'; expected LINEAR, STEP or CUBICSPLINE");
}

// The sampler's keys into `channel` (its path and interpolation set); `keys_left` counts down the
// file's key budget.
Status ReadKeys(const tinygltf::Model& model, const tinygltf::AnimationSampler& sampler,
                const std::string& what, std::size_t* keys_left, AnimationChannel* channel) {
  AccessorSpec input_spec{
      what + " input (times)", {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
  input_spec.max_count = *keys_left;
  input_spec.limit_noun = "keys (with the animations before it)";
  DEFORM_ASSIGN_OR_RETURN(AccessorValues times, ReadAccessor(model, sampler.input, input_spec));
  *keys_left -= static_cast<std::size_t>(times.count);
  for (int k = 0; k < times.count; ++k) {
    const double t = times.values[static_cast<std::size_t>(k)];
    if (t < 0) {
      return Status::InvalidArgument(what + " input (accessor " + std::to_string(sampler.input) +
                                     "): time " + std::to_string(k) + " is negative (" +
                                     std::to_string(t) + ")");
    }
    if (k > 0 && !(t > times.values[static_cast<std::size_t>(k) - 1])) {
      return Status::InvalidArgument(what + " input (accessor " + std::to_string(sampler.input) +
                                     "): times are not strictly increasing at key " +
                                     std::to_string(k));
    }
  }
  const bool cubic = channel->interpolation == AnimationInterpolation::kCubicSpline;
  if (cubic && times.count < 2) {
    return Status::InvalidArgument(what + " is CUBICSPLINE with " + std::to_string(times.count) +
                                   " key; it needs at least 2");
  }
  const bool rotation = channel->path == AnimationPath::kRotation;
  const std::string output_what =
      what + " output (" + (rotation ? "rotations" : "VEC3 values") + ")";
  AccessorSpec output_spec{output_what, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
  if (rotation) {
    // Rotations may also be normalized integers (glTF 2.0, 3.11: animation sampler outputs).
    static const std::initializer_list<int> kRotationType = {TINYGLTF_TYPE_VEC4};
    static const std::initializer_list<int> kRotationComponents = {
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
    output_spec.types = kRotationType;
    output_spec.components = kRotationComponents;
    output_spec.integers = AccessorSpec::IntegerNormalization::kRequired;
  }
  const std::uint64_t per_key = cubic ? 3 : 1;
  output_spec.exact_count = per_key * static_cast<std::uint64_t>(times.count);
  {
    // ReadAccessor's count message speaks of vertices; say what is expected here first.
    if (sampler.output >= 0 && static_cast<std::size_t>(sampler.output) < model.accessors.size()) {
      const std::size_t count = model.accessors[static_cast<std::size_t>(sampler.output)].count;
      if (count != output_spec.exact_count) {
        return Status::InvalidArgument(
            output_spec.what + " (accessor " + std::to_string(sampler.output) + ") has " +
            std::to_string(count) + " elements; expected " +
            std::to_string(output_spec.exact_count) +
            (cubic ? " (in-tangent, value and out-tangent per key)" : " (one per key)"));
      }
    }
  }
  DEFORM_ASSIGN_OR_RETURN(AccessorValues values, ReadAccessor(model, sampler.output, output_spec));
  if (rotation) {
    for (int k = 0; k < times.count; ++k) {
      const int element = cubic ? 3 * k + 1 : k;
      double norm2 = 0;
      for (int c = 0; c < 4; ++c) norm2 += values.at(element, c) * values.at(element, c);
      if (!(norm2 > 1e-12)) {
        return Status::InvalidArgument(output_spec.what + " (accessor " +
                                       std::to_string(sampler.output) + "): the rotation of key " +
                                       std::to_string(k) + " is a zero quaternion");
      }
    }
  }
  channel->times = std::move(times.values);
  channel->values = std::move(values.values);
  return Status::Ok();
}

}  // namespace

StatusOr<std::vector<GltfAnimation>> ReadAnimationChannels(const tinygltf::Model& model) {
  std::vector<GltfAnimation> animations;
  std::size_t keys_left = kMaxAnimationKeys;
  for (std::size_t a = 0; a < model.animations.size(); ++a) {
    const tinygltf::Animation& gltf = model.animations[a];
    GltfAnimation animation;
    animation.name = gltf.name.empty() ? "animation" + std::to_string(a) : gltf.name;
    const std::string where = "animation " + std::to_string(a) + " '" + animation.name + "'";
    if (gltf.channels.empty()) return Status::InvalidArgument(where + " has no channels");
    std::set<std::pair<int, int>> targeted;  // (node, path)
    bool any = false;
    for (std::size_t c = 0; c < gltf.channels.size(); ++c) {
      const tinygltf::AnimationChannel& gltf_channel = gltf.channels[c];
      const std::string what = where + " channel " + std::to_string(c);
      DEFORM_ASSIGN_OR_RETURN(const Target target, ReadTarget(model, gltf_channel, what));
      if (gltf_channel.sampler < 0 ||
          static_cast<std::size_t>(gltf_channel.sampler) >= gltf.samplers.size()) {
        return Status::InvalidArgument(what + " refers to sampler " +
                                       std::to_string(gltf_channel.sampler) +
                                       ", which does not exist (the animation has " +
                                       std::to_string(gltf.samplers.size()) + ")");
      }
      if (!target.used) continue;
      if (!targeted.emplace(gltf_channel.target_node, static_cast<int>(target.path)).second) {
        return Status::InvalidArgument(
            what + " targets node " + std::to_string(gltf_channel.target_node) + "'s " +
            gltf_channel.target_path + ", which an earlier channel of the animation targets");
      }
      const tinygltf::AnimationSampler& sampler =
          gltf.samplers[static_cast<std::size_t>(gltf_channel.sampler)];
      const std::string sampler_what = where + " sampler " + std::to_string(gltf_channel.sampler);
      AnimationChannel channel;
      channel.node = gltf_channel.target_node;
      channel.path = target.path;
      DEFORM_ASSIGN_OR_RETURN(channel.interpolation,
                              ReadInterpolation(sampler.interpolation, sampler_what));
      DEFORM_RETURN_IF_ERROR(ReadKeys(model, sampler, sampler_what, &keys_left, &channel));
      animation.start =
          any ? std::min(animation.start, channel.times.front()) : channel.times.front();
      animation.end = any ? std::max(animation.end, channel.times.back()) : channel.times.back();
      any = true;
      animation.channels.push_back(std::move(channel));
    }
    animations.push_back(std::move(animation));
  }
  return animations;
}

}  // namespace deform::gltf_internal
