// Internal to the glTF import: reading accessors (typed views into a glTF buffer) with every
// check the spec asks of them, so that no index, offset, stride or count in the file can make the
// reader step outside the loaded buffer data.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

// What an accessor must be to serve one purpose (POSITION, JOINTS_0, indices...).
struct AccessorSpec {
  std::string what;                       // for messages: "POSITION of primitive 0"
  std::initializer_list<int> types;       // TINYGLTF_TYPE_*
  std::initializer_list<int> components;  // TINYGLTF_COMPONENT_TYPE_*
  // Integer components: kNever (indices, JOINTS), or kRequired (normalized WEIGHTS).
  enum class IntegerNormalization { kNever, kRequired } integers = IntegerNormalization::kNever;
  // More elements are RESOURCE_EXHAUSTED (checked before anything is allocated).
  std::uint64_t max_count = std::numeric_limits<std::uint64_t>::max();
  const char* limit_noun = "elements";  // for that message: "vertices", "indices"
  // When non-zero, any other element count is INVALID_ARGUMENT (one element per vertex...).
  std::uint64_t exact_count = 0;
};

// An accessor's elements as doubles, `components` values an element, row after row. Normalized
// integers are mapped to [0, 1]; floats are checked finite.
struct AccessorValues {
  int count = 0;
  int components = 0;
  std::vector<double> values;

  double at(int element, int component) const {
    return values[static_cast<std::size_t>(element) * static_cast<std::size_t>(components) +
                  static_cast<std::size_t>(component)];
  }
};

// Reads accessor `index` of `model`. INVALID_ARGUMENT naming spec.what and the accessor when the
// index, type, component type, normalization, bufferView, stride, offset or count is not what the
// spec allows or does not fit the buffer data, for sparse accessors (not supported) and for
// non-finite floats, and for a count other than spec.exact_count; RESOURCE_EXHAUSTED beyond
// spec.max_count.
StatusOr<AccessorValues> ReadAccessor(const tinygltf::Model& model, int index,
                                      const AccessorSpec& spec);

}  // namespace deform::gltf_internal
