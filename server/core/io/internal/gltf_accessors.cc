#include "gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

namespace deform::gltf_internal {
namespace {

int ComponentSize(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

const char* ComponentName(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "an unknown component type";
  }
}

int TypeComponents(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

std::string TypeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "an unknown type";
  }
}

template <typename T>
T Load(const unsigned char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));  // glTF is little-endian, as are the hosts we build for
  return value;
}

double ReadComponent(const unsigned char* bytes, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = Load<std::uint8_t>(bytes);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = Load<std::uint16_t>(bytes);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return Load<std::uint32_t>(bytes);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = Load<std::int8_t>(bytes);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = Load<std::int16_t>(bytes);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    default:
      return Load<float>(bytes);
  }
}

template <typename T>
bool Contains(std::initializer_list<T> list, T value) {
  for (const T& item : list) {
    if (item == value) return true;
  }
  return false;
}

}  // namespace

StatusOr<AccessorValues> ReadAccessor(const tinygltf::Model& model, int index,
                                      const AccessorSpec& spec) {
  const std::string what = spec.what + " (accessor " + std::to_string(index) + ")";
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) {
    return Status::InvalidArgument(spec.what + " refers to accessor " + std::to_string(index) +
                                   ", which does not exist (the glTF has " +
                                   std::to_string(model.accessors.size()) + ")");
  }
  const tinygltf::Accessor& accessor = model.accessors[static_cast<std::size_t>(index)];
  if (!Contains(spec.types, accessor.type)) {
    return Status::InvalidArgument(what + " has type " + TypeName(accessor.type) + "; expected " +
                                   TypeName(*spec.types.begin()));
  }
  if (!Contains(spec.components, accessor.componentType)) {
    std::string expected;
    for (int c : spec.components)
      expected += (expected.empty() ? "" : " or ") + std::string(ComponentName(c));
    return Status::InvalidArgument(what + " has component type " +
                                   ComponentName(accessor.componentType) + "; expected " +
                                   expected);
  }
  const bool is_float = accessor.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (!is_float) {
    const bool want = spec.integers == AccessorSpec::IntegerNormalization::kRequired;
    if (accessor.normalized != want) {
      return Status::InvalidArgument(what + (want ? " holds integers that are not normalized "
                                                    "(integer weights must be normalized)"
                                                  : " is normalized; it must hold plain integers"));
    }
  }
  if (accessor.sparse.isSparse) {
    return Status::InvalidArgument(what + " is sparse; sparse accessors are not supported");
  }
  if (accessor.count == 0) return Status::InvalidArgument(what + " has no elements");
  if (spec.exact_count != 0 && accessor.count != spec.exact_count) {
    return Status::InvalidArgument(what + " has " + std::to_string(accessor.count) +
                                   " elements; expected " + std::to_string(spec.exact_count) +
                                   " (one per vertex)");
  }
  if (accessor.bufferView < 0 ||
      static_cast<std::size_t>(accessor.bufferView) >= model.bufferViews.size()) {
    return Status::InvalidArgument(what + " has no valid bufferView (" +
                                   std::to_string(accessor.bufferView) + ")");
  }
  const tinygltf::BufferView& view =
      model.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) {
    return Status::InvalidArgument(what + ": bufferView " + std::to_string(accessor.bufferView) +
                                   " refers to no buffer");
  }
  const std::vector<unsigned char>& data =
      model.buffers[static_cast<std::size_t>(view.buffer)].data;
  const int components = TypeComponents(accessor.type);
  const int component_size = ComponentSize(accessor.componentType);
  const std::uint64_t element_size = static_cast<std::uint64_t>(components) * component_size;
  const std::uint64_t stride = view.byteStride != 0 ? view.byteStride : element_size;
  if (stride < element_size || stride % static_cast<std::uint64_t>(component_size) != 0 ||
      stride > 252) {
    return Status::InvalidArgument(what + ": byteStride " + std::to_string(view.byteStride) +
                                   " does not fit elements of " + std::to_string(element_size) +
                                   " bytes (must be at least that, a multiple of the component "
                                   "size, at most 252)");
  }
  const std::uint64_t count = accessor.count;
  const std::uint64_t view_offset = view.byteOffset;
  const std::uint64_t view_length = view.byteLength;
  if (view_offset > data.size() || view_length > data.size() - view_offset) {
    return Status::InvalidArgument(what + ": bufferView " + std::to_string(accessor.bufferView) +
                                   " overruns its buffer of " + std::to_string(data.size()) +
                                   " bytes");
  }
  const std::uint64_t offset = accessor.byteOffset;
  // The last element ends at offset + stride * (count - 1) + element_size; count is bounded by
  // the view (at most 2^32 elements of at least one byte), so the product cannot overflow.
  if (offset > view_length || count - 1 > (view_length - offset) / stride ||
      offset + stride * (count - 1) + element_size > view_length) {
    return Status::InvalidArgument(what + ": " + std::to_string(count) + " elements from offset " +
                                   std::to_string(offset) + " (stride " + std::to_string(stride) +
                                   ") overrun bufferView " + std::to_string(accessor.bufferView) +
                                   " of " + std::to_string(view_length) + " bytes");
  }
  if (count > spec.max_count) {
    return Status::ResourceExhausted(what + " has " + std::to_string(count) + " " +
                                     spec.limit_noun + "; the limit is " +
                                     std::to_string(spec.max_count));
  }
  if (count > static_cast<std::uint64_t>(std::numeric_limits<int>::max() / 16)) {
    return Status::ResourceExhausted(what + " has " + std::to_string(count) +
                                     " elements, too many to read");
  }
  AccessorValues result;
  result.count = static_cast<int>(count);
  result.components = components;
  result.values.resize(static_cast<std::size_t>(count) * static_cast<std::size_t>(components));
  const unsigned char* base = data.data() + view_offset + offset;
  for (std::uint64_t e = 0; e < count; ++e) {
    for (int c = 0; c < components; ++c) {
      const double value =
          ReadComponent(base + e * stride + static_cast<std::uint64_t>(c) * component_size,
                        accessor.componentType, accessor.normalized);
      if (!std::isfinite(value)) {
        return Status::InvalidArgument(what + ": element " + std::to_string(e) + " is not finite");
      }
      result.values[e * static_cast<std::uint64_t>(components) + static_cast<std::uint64_t>(c)] =
          value;
    }
  }
  return result;
}

}  // namespace deform::gltf_internal
