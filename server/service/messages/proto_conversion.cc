#include "service/messages/proto_conversion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "service/base/request_limits.h"

namespace deform::service {
namespace {

void PutUint32(std::uint32_t bits, char* out) {
  out[0] = static_cast<char>(bits & 0xffu);
  out[1] = static_cast<char>((bits >> 8) & 0xffu);
  out[2] = static_cast<char>((bits >> 16) & 0xffu);
  out[3] = static_cast<char>((bits >> 24) & 0xffu);
}

// Zero fields keep `defaults`; set fields must be valid weights.
StatusOr<JointMaterial> MaterialFromProto(const v1::JointMaterial& proto,
                                          const JointMaterial& defaults, const std::string& what) {
  JointMaterial material = defaults;
  if (proto.rigid() != 0) material.rigid = proto.rigid();
  if (proto.soft() != 0) material.soft = proto.soft();
  if (proto.seam() != 0) material.seam = proto.seam();
  DEFORM_RETURN_IF_ERROR(CheckJointMaterial(material, what));
  return material;
}

StatusOr<int> JointOf(const Skeleton& skeleton, const std::string& name, const char* what) {
  auto joint = skeleton.FindJoint(name);
  if (!joint.ok()) {
    return Status::InvalidArgument(std::string(what) + ": " + joint.status().message());
  }
  return *joint;
}

// The joint index of a stiffness term, which must have a joint region.
StatusOr<int> RegionJointOf(const DeformationModel& model, const std::string& name,
                            const char* what) {
  DEFORM_ASSIGN_OR_RETURN(const int joint, JointOf(model.skeleton(), name, what));
  const Status has_region =
      RegionOfJoint(model.joint_regions(), model.skeleton(), joint).status().WithContext(what);
  if (!has_region.ok()) return has_region;
  return joint;
}

}  // namespace

Status ToolFromProto(const v1::ToolState& state, int index, const Eigen::Vector3d& lower,
                     const Eigen::Vector3d& upper, Tool* tool) {
  const std::string name = "tool " + std::to_string(index);
  switch (state.shape()) {
    case v1::ToolState::SHAPE_SPHERE:
      tool->shape = Tool::Shape::kSphere;
      break;
    case v1::ToolState::SHAPE_CAPSULE:
      tool->shape = Tool::Shape::kCapsule;
      if (!state.has_end()) return Status::InvalidArgument(name + ": a capsule needs `end`");
      break;
    default:
      return Status::InvalidArgument(name + ": shape must be SHAPE_SPHERE or SHAPE_CAPSULE");
  }
  if (!state.has_center()) return Status::InvalidArgument(name + ": `center` is unset");
  tool->a = Eigen::Vector3d(state.center().x(), state.center().y(), state.center().z());
  tool->b = tool->shape == Tool::Shape::kCapsule
                ? Eigen::Vector3d(state.end().x(), state.end().y(), state.end().z())
                : tool->a;
  tool->radius = state.radius();
  return ValidateTool(*tool, index, lower, upper);
}

StatusOr<ModelOptions> ModelOptionsFromProto(const v1::MethodOptions& proto,
                                             const Skeleton& skeleton) {
  DEFORM_RETURN_IF_ERROR(CheckMethodOptionStrings(proto));
  ModelOptions options = ModelOptions::Paper();
  if (proto.region_radius_factor() != 0) {
    if (!std::isfinite(proto.region_radius_factor()) || proto.region_radius_factor() < 0) {
      return Status::InvalidArgument("region_radius_factor must be positive and finite, got " +
                                     std::to_string(proto.region_radius_factor()))
          .WithSubject("region_radius_factor");
    }
    options.regions.radius_factor = proto.region_radius_factor();
  }
  for (int k = 0; k < proto.region_radii_size(); ++k) {
    const v1::JointRadius& radius = proto.region_radii(k);
    const std::string path = "region_radii[" + std::to_string(k) + "]";
    const StatusOr<int> found = JointOf(skeleton, radius.joint(), "region_radii");
    if (!found.ok()) return InField(found.status(), path + ".joint");
    const int joint = *found;
    if (!std::isfinite(radius.radius()) || radius.radius() <= 0) {
      return Status::InvalidArgument("region radius of joint '" + radius.joint() +
                                     "' must be positive and finite, got " +
                                     std::to_string(radius.radius()))
          .WithSubject(path + ".radius");
    }
    options.regions.explicit_radius.emplace_back(joint, radius.radius());
  }
  if (proto.has_default_material()) {
    const StatusOr<JointMaterial> material =
        MaterialFromProto(proto.default_material(), JointMaterial{}, "default material");
    if (!material.ok()) return InField(material.status(), "default_material");
    options.default_material = *material;
  }
  switch (proto.rotation_blend()) {
    case v1::ROTATION_BLEND_UNSPECIFIED:
    case v1::ROTATION_BLEND_QUATERNION:
      options.rotation_blend = RotationBlend::kQuaternion;
      break;
    case v1::ROTATION_BLEND_LINEAR:
      options.rotation_blend = RotationBlend::kLinear;
      break;
    default:
      return Status::InvalidArgument("unknown rotation_blend " +
                                     std::to_string(proto.rotation_blend()))
          .WithSubject("rotation_blend");
  }
  // DeformationModel::Build checks the range (INVALID_ARGUMENT naming the field).
  if (proto.has_rigid_weight_tolerance()) {
    options.rigid_weight_tolerance = proto.rigid_weight_tolerance();
  }
  // 0 keeps the default; DeformationModel::Build checks the range.
  if (proto.linear_blend_segments() != 0) {
    options.linear_blend_segments = static_cast<int>(
        std::min<std::uint32_t>(proto.linear_blend_segments(), std::numeric_limits<int>::max()));
  }
  return options;
}

StatusOr<ConstraintOptions> ConstraintOptionsFromProto(const v1::Constraints& proto) {
  ConstraintOptions options;
  if (proto.has_contacts() && !proto.contacts()) options.max_contacts = 0;
  if (proto.has_keep_volume()) options.keep_volume = proto.keep_volume();
  if (proto.has_contact_margin()) {
    const double margin = proto.contact_margin();
    if (!std::isfinite(margin) || margin < 0 || margin > 0.1) {
      return Status::InvalidArgument("contact_margin must be in [0, 0.1] of the diagonal, got " +
                                     std::to_string(margin))
          .WithSubject("contact_margin");
    }
    options.contact_margin = margin;
  }
  return options;
}

void ConstraintOptionsToProto(const ConstraintOptions& options, v1::Constraints* proto) {
  proto->set_contacts(options.contacts());
  proto->set_keep_volume(options.keep_volume);
  proto->set_contact_margin(options.contact_margin);
}

StatusOr<Stiffness> StiffnessFromProto(const v1::StiffnessUpdate& proto,
                                       const DeformationModel& model,
                                       const std::vector<int>& client_order) {
  DEFORM_RETURN_IF_ERROR(CheckStiffnessStrings(proto));
  Stiffness stiffness;
  for (int k = 0; k < proto.joint_materials_size(); ++k) {
    const v1::JointMaterialUpdate& update = proto.joint_materials(k);
    const std::string path = "joint_materials[" + std::to_string(k) + "]";
    const StatusOr<int> joint = RegionJointOf(model, update.joint(), "joint_materials");
    if (!joint.ok()) return InField(joint.status(), path + ".joint");
    const StatusOr<JointMaterial> material =
        MaterialFromProto(update.material(), model.options().default_material,
                          "material of joint '" + update.joint() + "'");
    if (!material.ok()) return InField(material.status(), path + ".material");
    stiffness.joint_materials.emplace_back(*joint, *material);
  }
  for (int k = 0; k < proto.region_weights_size(); ++k) {
    const v1::RegionWeight& weight = proto.region_weights(k);
    const std::string path = "region_weights[" + std::to_string(k) + "]";
    const StatusOr<int> joint = RegionJointOf(model, weight.joint(), "region_weights");
    if (!joint.ok()) return InField(joint.status(), path + ".joint");
    DEFORM_RETURN_IF_ERROR(InField(
        CheckMaterialWeight(weight.weight(), "region weight of joint '" + weight.joint() + "'"),
        path + ".weight"));
    stiffness.region_weights.emplace_back(*joint, weight.weight());
  }
  if (proto.vertex_indices_size() != proto.vertex_weights_size()) {
    return Status::InvalidArgument(
               "vertex_indices has " + std::to_string(proto.vertex_indices_size()) +
               " entries but vertex_weights has " + std::to_string(proto.vertex_weights_size()))
        .WithSubject("vertex_weights");
  }
  const std::uint32_t vertices = static_cast<std::uint32_t>(
      client_order.empty() ? model.mesh().num_vertices() : client_order.size());
  stiffness.vertex_weights.reserve(proto.vertex_indices_size());
  for (int k = 0; k < proto.vertex_indices_size(); ++k) {
    const std::uint32_t vertex = proto.vertex_indices(k);
    if (vertex >= vertices) {
      return Status::InvalidArgument("vertex_indices[" + std::to_string(k) +
                                     "] = " + std::to_string(vertex) + " but the mesh has " +
                                     std::to_string(vertices) + " vertices")
          .WithSubject("vertex_indices[" + std::to_string(k) + "]");
    }
    DEFORM_RETURN_IF_ERROR(InField(
        CheckMaterialWeight(proto.vertex_weights(k), "weight of vertex " + std::to_string(vertex)),
        "vertex_weights[" + std::to_string(k) + "]"));
    const int solved = client_order.empty() ? static_cast<int>(vertex) : client_order[vertex];
    stiffness.vertex_weights.emplace_back(solved, proto.vertex_weights(k));
  }
  return stiffness;
}

void FillMeshSummary(const MeshEntry& entry, v1::MeshSummary* summary) {
  const DeformationModel& model = *entry.model;
  const Skeleton& skeleton = model.skeleton();
  summary->set_mesh_id(entry.id);
  summary->set_name(entry.name);
  summary->set_vertex_count(static_cast<std::uint32_t>(entry.client_vertex_count()));
  summary->set_solved_vertex_count(static_cast<std::uint32_t>(model.mesh().num_vertices()));
  summary->set_triangle_count(static_cast<std::uint32_t>(model.mesh().num_triangles()));
  summary->set_bone_count(static_cast<std::uint32_t>(skeleton.num_bones()));
  summary->set_factor_bytes(entry.factor_bytes);
  summary->set_factor_float32(model.default_factorization()->factor().stores_float32());
  summary->set_float32_probe_error(model.default_factorization()->float32_probe_error());
  summary->set_precompute_ms(entry.precompute_ms);
  summary->set_factor_ms(entry.factor_ms);
  summary->set_open_streams(static_cast<std::uint32_t>(entry.open_streams.load()));
  summary->set_rotation_blend(model.options().rotation_blend == RotationBlend::kLinear
                                  ? v1::ROTATION_BLEND_LINEAR
                                  : v1::ROTATION_BLEND_QUATERNION);
  const LinearPoseResponse* response = model.default_factorization()->linear_response();
  summary->set_linear_response_bytes(response != nullptr ? response->bytes() : 0);
  summary->clear_joints();
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const Joint& joint = skeleton.joint(j);
    v1::JointInfo* info = summary->add_joints();
    info->set_name(joint.name);
    info->set_index(static_cast<std::uint32_t>(j));
    for (int c = 0; c < 3; ++c) info->add_rest_position(joint.rest_position[c]);
    for (const DegreeOfFreedom& dof : joint.dofs) {
      v1::DegreeOfFreedom* out = info->add_dofs();
      out->set_name(dof.name);
      for (int c = 0; c < 3; ++c) out->add_axis(dof.axis[c]);
      out->set_min_degrees(dof.min_degrees);
      out->set_max_degrees(dof.max_degrees);
    }
    info->set_has_region(FindJointRegion(model.joint_regions(), j) >= 0);
  }
  summary->clear_bones();
  for (const Bone& bone : skeleton.bones()) {
    v1::BoneInfo* info = summary->add_bones();
    info->set_head_joint(static_cast<std::uint32_t>(bone.head_joint));
    info->set_tail_joint(static_cast<std::uint32_t>(bone.tail_joint));
    info->set_parent_bone(bone.parent_bone);
  }
  summary->set_binding(model.weights_given() ? v1::BINDING_WEIGHTS : v1::BINDING_THROUGH_BODY);
  summary->clear_warnings();
  for (const std::string& warning : entry.file_metadata.warnings) summary->add_warnings(warning);
  for (const std::string& warning : model.binding_report().warnings) summary->add_warnings(warning);
  if (const std::size_t unused = entry.file_metadata.unused_file_vertices.size(); unused > 0) {
    summary->add_warnings(std::to_string(unused) +
                          " of the file's vertices are used by no triangle: each follows the used "
                          "vertex before it in the file (frames give it that vertex's position)");
  }
  summary->set_units(entry.file_metadata.units);
  summary->set_up_axis(entry.file_metadata.up_axis);
  summary->clear_bone_surfaces();
  if (const BoneContacts* bones = entry.bones()) {
    for (int s = 0; s < bones->num_surfaces(); ++s) {
      const BoneSurface& surface = bones->surface(s);
      v1::BoneSurfaceInfo* info = summary->add_bone_surfaces();
      info->set_name(surface.name);
      info->set_bone(static_cast<std::uint32_t>(surface.bone));
      info->set_blend_bone(surface.blend_bone);
      info->set_blend(surface.blend);
      info->set_vertex_count(static_cast<std::uint32_t>(surface.mesh.num_vertices()));
      info->set_triangle_count(static_cast<std::uint32_t>(surface.mesh.num_triangles()));
    }
  }
  ConstraintOptionsToProto(entry.constraints.options, summary->mutable_constraints());
}

void FillMeshGeometry(const MeshEntry& entry, v1::GetMeshInfoResponse* info) {
  const TriangleMesh& mesh = entry.model->mesh();
  const std::vector<int>& order = entry.file_metadata.file_vertex_to_mesh;
  std::string* positions = info->mutable_rest_positions();
  positions->resize(static_cast<std::size_t>(entry.client_vertex_count()) * 3 * 4);
  EncodeInClientOrder(mesh.vertices.data(), mesh.num_vertices(), order, positions->data());
  // Triangles name client vertices: each solved vertex by the first file vertex welded into it
  // (never one that no triangle uses and that only follows it).
  std::vector<int> client_of(mesh.num_vertices(), -1);
  const std::vector<int>& unused = entry.file_metadata.unused_file_vertices;
  auto next_unused = unused.rbegin();
  for (int f = static_cast<int>(order.size()) - 1; f >= 0; --f) {
    while (next_unused != unused.rend() && *next_unused > f) ++next_unused;
    if (next_unused != unused.rend() && *next_unused == f) continue;
    client_of[order[f]] = f;
  }
  std::string* triangles = info->mutable_triangles();
  const std::size_t indices = static_cast<std::size_t>(mesh.num_triangles()) * 3;
  triangles->resize(indices * 4);
  const int* source = mesh.triangles.data();
  for (std::size_t k = 0; k < indices; ++k) {
    const int vertex = order.empty() ? source[k] : client_of[source[k]];
    PutUint32(static_cast<std::uint32_t>(vertex), triangles->data() + 4 * k);
  }
  info->clear_bone_surfaces();
  if (const BoneContacts* bones = entry.bones()) {
    for (int s = 0; s < bones->num_surfaces(); ++s) {
      const TriangleMesh& surface = bones->surface(s).mesh;
      v1::BoneSurfaceGeometry* geometry = info->add_bone_surfaces();
      std::string* rest = geometry->mutable_rest_positions();
      rest->resize(static_cast<std::size_t>(surface.num_vertices()) * 12);
      EncodeFloat32(surface.vertices.data(), static_cast<std::size_t>(surface.num_vertices()) * 3,
                    rest->data());
      std::string* faces = geometry->mutable_triangles();
      const std::size_t count = static_cast<std::size_t>(surface.num_triangles()) * 3;
      faces->resize(count * 4);
      for (std::size_t k = 0; k < count; ++k) {
        PutUint32(static_cast<std::uint32_t>(surface.triangles.data()[k]), faces->data() + 4 * k);
      }
    }
  }
}

std::size_t BoneSurfaceTransformBytes(const BoneContacts* bones) {
  return bones != nullptr ? static_cast<std::size_t>(bones->num_surfaces()) * 12 * sizeof(float)
                          : 0;
}

void EncodeBoneSurfaceTransforms(const BoneContacts& bones, const Skeleton& skeleton,
                                 const std::vector<RigidTransform>& bone_transforms, char* out) {
  for (int s = 0; s < bones.num_surfaces(); ++s) {
    const RigidTransform motion = BoneSurfaceTransform(bones.surface(s), skeleton, bone_transforms);
    const Eigen::Matrix3d rotation = motion.rotation.toRotationMatrix();
    double values[12];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) values[3 * r + c] = rotation(r, c);
    }
    for (int c = 0; c < 3; ++c) values[9 + c] = motion.translation[c];
    EncodeFloat32(values, 12, out + 48 * static_cast<std::size_t>(s));
  }
}

void EncodeInClientOrder(const double* xyz, int solved_vertices, const std::vector<int>& order,
                         char* out) {
  if (order.empty()) {
    EncodeFloat32(xyz, static_cast<std::size_t>(solved_vertices) * 3, out);
    return;
  }
  for (std::size_t f = 0; f < order.size(); ++f) {
    EncodeFloat32(xyz + 3 * static_cast<std::size_t>(order[f]), 3, out + 12 * f);
  }
}

void EncodeFloat32(const double* values, std::size_t count, char* out) {
  for (std::size_t k = 0; k < count; ++k) {
    const float value = static_cast<float>(values[k]);
    std::uint32_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    PutUint32(bits, out + 4 * k);
  }
}

}  // namespace deform::service
