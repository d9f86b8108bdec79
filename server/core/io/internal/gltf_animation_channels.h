// Internal to the glTF animation reader: the file's animations as channels with their keys, every
// rule of core/io/gltf_animation.h checked (types, counts, times, indices, targets).
#pragma once

#include <vector>

#include "core/base/status.h"
#include "core/io/gltf_animation.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

StatusOr<std::vector<GltfAnimation>> ReadAnimationChannels(const tinygltf::Model& model);

}  // namespace deform::gltf_internal
