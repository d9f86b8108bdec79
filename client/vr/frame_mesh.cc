#include "vr/frame_mesh.h"

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace deform::vr {
namespace {

std::uint32_t ReadUint32LittleEndian(const char* bytes) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes);
  return static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8) |
         (static_cast<std::uint32_t>(b[2]) << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
}

float ReadFloat32LittleEndian(const char* bytes) {
  const std::uint32_t bits = ReadUint32LittleEndian(bytes);
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace

StatusOr<TriangleMesh> MeshFromBuffers(const std::string& positions, const std::string& triangles) {
  constexpr std::size_t kRecordBytes = 12;  // three 4-byte values
  if (positions.empty() || positions.size() % kRecordBytes != 0) {
    return Status::InvalidArgument("frame positions hold " + std::to_string(positions.size()) +
                                   " bytes, not a positive multiple of 12");
  }
  if (triangles.empty() || triangles.size() % kRecordBytes != 0) {
    return Status::InvalidArgument("mesh triangles hold " + std::to_string(triangles.size()) +
                                   " bytes, not a positive multiple of 12");
  }
  const std::size_t vertex_count = positions.size() / kRecordBytes;
  const std::size_t triangle_count = triangles.size() / kRecordBytes;

  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(vertex_count), 3);
  for (std::size_t v = 0; v < vertex_count; ++v) {
    for (int c = 0; c < 3; ++c) {
      mesh.vertices(static_cast<Eigen::Index>(v), c) =
          ReadFloat32LittleEndian(positions.data() + kRecordBytes * v + 4 * c);
    }
  }
  mesh.triangles.resize(static_cast<Eigen::Index>(triangle_count), 3);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t index =
          ReadUint32LittleEndian(triangles.data() + kRecordBytes * t + 4 * c);
      if (index >= vertex_count) {
        return Status::InvalidArgument("triangle " + std::to_string(t) + " names vertex " +
                                       std::to_string(index) + " of " +
                                       std::to_string(vertex_count));
      }
      mesh.triangles(static_cast<Eigen::Index>(t), c) = static_cast<int>(index);
    }
  }
  return mesh;
}

}  // namespace deform::vr
