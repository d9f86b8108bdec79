#include "service/base/request_limits.h"

#include <limits>

#include "service/base/log_text.h"

namespace deform::service {
namespace {

std::string Indexed(const char* field, int index, const char* member) {
  return std::string(field) + "[" + std::to_string(index) + "]." + member;
}

// a + b, or the largest uint64 when the sum would not fit.
std::uint64_t SaturatingAdd(std::uint64_t a, std::uint64_t b) {
  return a > std::numeric_limits<std::uint64_t>::max() - b
             ? std::numeric_limits<std::uint64_t>::max()
             : a + b;
}

}  // namespace

Status CheckLength(std::string_view value, std::size_t limit, std::string_view field) {
  if (value.size() <= limit) return Status::Ok();
  return Status::InvalidArgument(std::string(field) + " is " + std::to_string(value.size()) +
                                 " bytes long, over the limit of " + std::to_string(limit) +
                                 " bytes")
      .WithSubject(std::string(field));
}

Status InField(const Status& status, const std::string& field) {
  if (status.code() != StatusCode::kInvalidArgument) return status;
  return status.WithSubject(status.subject().empty() ? field : field + "." + status.subject());
}

std::string EchoForClient(std::string_view text) {
  std::string echo = EscapeForLog(text, kMaxEchoBytes);
  if (text.size() > kMaxEchoBytes) echo += " (" + std::to_string(text.size()) + " bytes)";
  return echo;
}

std::string BoundStatusMessage(std::string message) {
  if (message.size() <= kMaxStatusMessageBytes) return message;
  const std::string tail = "... (" + std::to_string(message.size()) + " bytes)";
  message.resize(kMaxStatusMessageBytes - tail.size());
  return message + tail;
}

Status CheckPoseStrings(const v1::PoseUpdate& pose) {
  for (int k = 0; k < pose.angles_size(); ++k) {
    const v1::JointAngle& angle = pose.angles(k);
    DEFORM_RETURN_IF_ERROR(
        CheckLength(angle.joint(), kMaxJointNameBytes, Indexed("angles", k, "joint")));
    DEFORM_RETURN_IF_ERROR(
        CheckLength(angle.axis(), kMaxAxisNameBytes, Indexed("angles", k, "axis")));
  }
  for (int k = 0; k < pose.rotations_size(); ++k) {
    DEFORM_RETURN_IF_ERROR(CheckLength(pose.rotations(k).joint(), kMaxJointNameBytes,
                                       Indexed("rotations", k, "joint")));
  }
  return Status::Ok();
}

Status CheckStiffnessStrings(const v1::StiffnessUpdate& stiffness) {
  for (int k = 0; k < stiffness.joint_materials_size(); ++k) {
    DEFORM_RETURN_IF_ERROR(CheckLength(stiffness.joint_materials(k).joint(), kMaxJointNameBytes,
                                       Indexed("joint_materials", k, "joint")));
  }
  for (int k = 0; k < stiffness.region_weights_size(); ++k) {
    DEFORM_RETURN_IF_ERROR(CheckLength(stiffness.region_weights(k).joint(), kMaxJointNameBytes,
                                       Indexed("region_weights", k, "joint")));
  }
  return Status::Ok();
}

Status CheckMethodOptionStrings(const v1::MethodOptions& options) {
  for (int k = 0; k < options.region_radii_size(); ++k) {
    DEFORM_RETURN_IF_ERROR(CheckLength(options.region_radii(k).joint(), kMaxJointNameBytes,
                                       Indexed("region_radii", k, "joint")));
  }
  return Status::Ok();
}

Status CheckLoadHeaderStrings(const v1::LoadMeshHeader& header) {
  DEFORM_RETURN_IF_ERROR(CheckLength(header.name(), kMaxMeshNameBytes, "name"));
  const auto& bones = header.upload().bone_surfaces();
  for (int i = 0; i < bones.size(); ++i) {
    const std::string field = "upload.bone_surfaces[" + std::to_string(i) + "]";
    DEFORM_RETURN_IF_ERROR(CheckLength(bones[i].name(), kMaxMeshNameBytes, field + ".name"));
    DEFORM_RETURN_IF_ERROR(CheckLength(bones[i].bone(), kMaxJointNameBytes, field + ".bone"));
    DEFORM_RETURN_IF_ERROR(
        CheckLength(bones[i].blend_bone(), kMaxJointNameBytes, field + ".blend_bone"));
  }
  const Status options = CheckMethodOptionStrings(header.options());
  return InField(options.WithContext("options"), "options");
}

Status CheckUploadSize(std::uint64_t mesh_bytes, std::uint64_t skeleton_bytes,
                       std::uint64_t weights_bytes, std::uint64_t limit) {
  const std::uint64_t total =
      SaturatingAdd(SaturatingAdd(mesh_bytes, skeleton_bytes), weights_bytes);
  if (total <= limit) return Status::Ok();
  const bool saturated = total == std::numeric_limits<std::uint64_t>::max() &&
                         (skeleton_bytes != 0 || weights_bytes != 0);
  return Status::ResourceExhausted(
             "upload of " + (saturated ? std::string("more than ") : std::string()) +
             std::to_string(total) + " bytes (mesh " + std::to_string(mesh_bytes) + ", skeleton " +
             std::to_string(skeleton_bytes) + ", weights " + std::to_string(weights_bytes) +
             ") exceeds the limit of " + std::to_string(limit) + " bytes")
      .WithLimit("server", "--max-upload-mb");
}

}  // namespace deform::service
