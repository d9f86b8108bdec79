// Internal to the glTF import: turning untrusted bytes into a tinygltf::Model without reading
// anything else.
//
// tinygltf trusts parts of its input (2.7: a GLB's BIN chunk may be read 8 bytes past the stated
// length; an image's bufferView offset is not checked against its buffer; deeply nested "extras"
// recurse without bound). So the bytes are checked here first: the GLB container strictly by the
// spec, the JSON's nesting depth, every buffer and image URI (data URIs only: an external URI is
// INVALID_ARGUMENT naming it), required extensions, and every bufferView against its buffer. Then
// tinygltf parses with file callbacks that refuse every path and an image loader that ignores
// images, so that an uploaded file never makes the server read anything but the given bytes.
#pragma once

#include <string_view>

#include "core/base/status.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

// The deepest JSON nesting accepted (objects and arrays). glTF itself needs 5; extras rarely more.
inline constexpr int kMaxJsonDepth = 64;

// Detects .glb by its magic ("glTF"); anything else is taken as .gltf JSON.
bool IsGlb(std::string_view bytes);

// Parses `bytes` (.gltf JSON or .glb) into `model`. INVALID_ARGUMENT naming the problem.
Status LoadGltfModel(std::string_view bytes, tinygltf::Model* model);

}  // namespace deform::gltf_internal
