// The client-side helpers declared at the end of deform_client.h.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/base/pose_spec.h"
#include "core/base/tool_spec.h"
#include "deform_client.h"

namespace deform::client {

bool ParsePoseAngles(const std::string& spec, deform::v1::PoseUpdate* pose, std::string* error) {
  StatusOr<std::vector<PoseSpecTerm>> terms = ParsePoseSpecTerms(spec);
  if (!terms.ok()) {
    if (error != nullptr) *error = terms.status().ToString();
    return false;
  }
  for (const PoseSpecTerm& term : *terms) {
    deform::v1::JointAngle* angle = pose->add_angles();
    angle->set_joint(term.joint);
    angle->set_axis(term.axis);
    angle->set_degrees(term.degrees);
  }
  return true;
}

void AddSphereTool(double x, double y, double z, double radius, deform::v1::PoseUpdate* pose) {
  deform::v1::ToolState* tool = pose->add_tools();
  tool->set_shape(deform::v1::ToolState::SHAPE_SPHERE);
  tool->mutable_center()->set_x(x);
  tool->mutable_center()->set_y(y);
  tool->mutable_center()->set_z(z);
  tool->set_radius(radius);
}

void AddCapsuleTool(const double center[3], const double end[3], double radius,
                    deform::v1::PoseUpdate* pose) {
  deform::v1::ToolState* tool = pose->add_tools();
  tool->set_shape(deform::v1::ToolState::SHAPE_CAPSULE);
  tool->mutable_center()->set_x(center[0]);
  tool->mutable_center()->set_y(center[1]);
  tool->mutable_center()->set_z(center[2]);
  tool->mutable_end()->set_x(end[0]);
  tool->mutable_end()->set_y(end[1]);
  tool->mutable_end()->set_z(end[2]);
  tool->set_radius(radius);
}

bool AddToolSpec(const std::string& spec, deform::v1::PoseUpdate* pose, std::string* error) {
  StatusOr<ToolSpec> parsed = ParseToolSpecText(spec);
  if (!parsed.ok()) {
    if (error != nullptr) *error = parsed.status().ToString();
    return false;
  }
  if (parsed->capsule) {
    AddCapsuleTool(parsed->a, parsed->b, parsed->radius, pose);
  } else {
    AddSphereTool(parsed->a[0], parsed->a[1], parsed->a[2], parsed->radius, pose);
  }
  return true;
}

std::vector<float> DecodePositions(const std::string& bytes) {
  std::vector<float> values(bytes.size() / 4);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::uint32_t bits = static_cast<std::uint32_t>(data[4 * k]) |
                               static_cast<std::uint32_t>(data[4 * k + 1]) << 8 |
                               static_cast<std::uint32_t>(data[4 * k + 2]) << 16 |
                               static_cast<std::uint32_t>(data[4 * k + 3]) << 24;
    std::memcpy(&values[k], &bits, sizeof(float));
  }
  return values;
}

std::vector<BoneSurfaceMotion> DecodeBoneTransforms(const std::string& bytes) {
  constexpr std::size_t kBytes = 12 * sizeof(float);
  if (bytes.size() % kBytes != 0) return {};
  const std::vector<float> values = DecodePositions(bytes);
  std::vector<BoneSurfaceMotion> motions(bytes.size() / kBytes);
  for (std::size_t s = 0; s < motions.size(); ++s) {
    std::copy_n(values.begin() + 12 * s, 9, motions[s].rotation);
    std::copy_n(values.begin() + 12 * s + 9, 3, motions[s].translation);
  }
  return motions;
}

std::int64_t MonotonicNanos() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

deform::v1::MeshFormat MeshFormatFromPath(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  if (dot == std::string::npos) return deform::v1::MESH_FORMAT_UNSPECIFIED;
  std::string extension = path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == "obj") return deform::v1::MESH_FORMAT_OBJ;
  if (extension == "ply") return deform::v1::MESH_FORMAT_PLY;
  if (extension == "stl") return deform::v1::MESH_FORMAT_STL;
  if (extension == "off") return deform::v1::MESH_FORMAT_OFF;
  if (extension == "gltf" || extension == "glb") return deform::v1::MESH_FORMAT_GLTF;
  return deform::v1::MESH_FORMAT_UNSPECIFIED;
}

}  // namespace deform::client
