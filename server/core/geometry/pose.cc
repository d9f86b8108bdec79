#include "core/geometry/pose.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace deform {
namespace {

constexpr double kDegreesToRadians = M_PI / 180.0;

std::vector<std::string_view> Split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return parts;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

StatusOr<double> ParseDegrees(std::string_view text) {
  const std::string s(text);
  char* end = nullptr;
  const double value = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) {
    return Status::InvalidArgument("'" + s + "' is not a number of degrees");
  }
  if (!std::isfinite(value)) return Status::InvalidArgument("angle '" + s + "' is not finite");
  return value;
}

}  // namespace

Pose Pose::Rest(const Skeleton& skeleton) {
  Pose pose;
  pose.joint_rotations.assign(skeleton.num_joints(), Eigen::Quaterniond::Identity());
  return pose;
}

StatusOr<std::vector<PoseTerm>> ParsePoseSpec(std::string_view spec, const Skeleton& skeleton) {
  std::vector<PoseTerm> terms;
  spec = Trim(spec);
  if (spec.empty() || spec == "rest") return terms;
  for (std::string_view raw : Split(spec, ',')) {
    const std::string_view item = Trim(raw);
    const std::vector<std::string_view> fields = Split(item, ':');
    if (fields.size() != 3) {
      return Status::InvalidArgument("pose term '" + std::string(item) +
                                     "' is not JOINT:AXIS:DEGREES");
    }
    PoseTerm term;
    auto joint = skeleton.FindJoint(Trim(fields[0]));
    if (!joint.ok()) return Status::InvalidArgument(joint.status().message());
    term.joint = *joint;
    const std::string_view axis = Trim(fields[1]);
    if (axis == "x" || axis == "y" || axis == "z") {
      term.axis = Eigen::Vector3d::Unit(axis[0] - 'x');
    } else {
      const auto& dofs = skeleton.joint(term.joint).dofs;
      const auto it = std::find_if(dofs.begin(), dofs.end(),
                                   [&](const DegreeOfFreedom& d) { return d.name == axis; });
      if (it == dofs.end()) {
        std::string known = "x, y, z";
        for (const auto& d : dofs) known += ", " + d.name;
        return Status::InvalidArgument("joint '" + skeleton.joint(term.joint).name +
                                       "' has no axis '" + std::string(axis) +
                                       "' (known: " + known + ")");
      }
      term.dof = static_cast<int>(it - dofs.begin());
      term.axis = it->axis;
    }
    DEFORM_ASSIGN_OR_RETURN(term.degrees, ParseDegrees(Trim(fields[2])));
    terms.push_back(term);
  }
  return terms;
}

StatusOr<int> PoseFromTerms(const Skeleton& skeleton, const std::vector<PoseTerm>& terms,
                            Pose* pose) {
  pose->joint_rotations.resize(skeleton.num_joints());
  std::fill(pose->joint_rotations.begin(), pose->joint_rotations.end(),
            Eigen::Quaterniond::Identity());
  pose->root = RigidTransform();
  int clamped = 0;
  for (const PoseTerm& term : terms) {
    if (term.joint < 0 || term.joint >= skeleton.num_joints()) {
      return Status::InvalidArgument("pose names joint " + std::to_string(term.joint) +
                                     " but the skeleton has " +
                                     std::to_string(skeleton.num_joints()));
    }
    if (!std::isfinite(term.degrees)) {
      return Status::InvalidArgument("angle for joint '" + skeleton.joint(term.joint).name +
                                     "' is not finite");
    }
    double degrees = term.degrees;
    Eigen::Vector3d axis = term.axis;
    if (term.dof >= 0) {
      const auto& dofs = skeleton.joint(term.joint).dofs;
      if (term.dof >= static_cast<int>(dofs.size())) {
        return Status::InvalidArgument("joint '" + skeleton.joint(term.joint).name +
                                       "' has no degree of freedom " + std::to_string(term.dof));
      }
      const DegreeOfFreedom& dof = dofs[term.dof];
      axis = dof.axis;
      const double limited = std::clamp(degrees, dof.min_degrees, dof.max_degrees);
      if (limited != degrees) ++clamped;
      degrees = limited;
    } else if (!axis.allFinite() || axis.norm() < 1e-12) {
      return Status::InvalidArgument("pose axis for joint '" + skeleton.joint(term.joint).name +
                                     "' is zero or not finite");
    }
    Eigen::Quaterniond& q = pose->joint_rotations[term.joint];
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kDegreesToRadians, axis.normalized()));
    q.normalize();
  }
  return clamped;
}

void ForwardKinematics(const Skeleton& skeleton, const Pose& pose,
                       std::vector<RigidTransform>* bone_transforms) {
  bone_transforms->resize(skeleton.num_bones());
  for (int k : skeleton.BonesParentsFirst()) {
    const Bone& bone = skeleton.bone(k);
    const Eigen::Vector3d& centre = skeleton.joint(bone.head_joint).rest_position;
    // Rotation about the head joint's rest position, in the rest frame...
    RigidTransform local;
    local.rotation = pose.joint_rotations[bone.head_joint];
    local.translation = centre - local.rotation * centre;
    // ...then carried by the parent bone (or the root transform).
    const RigidTransform& parent =
        bone.parent_bone >= 0 ? (*bone_transforms)[bone.parent_bone] : pose.root;
    (*bone_transforms)[k] = parent * local;
  }
}

Eigen::Vector3d PosedJointPosition(const Skeleton& skeleton, const Pose& pose,
                                   const std::vector<RigidTransform>& bone_transforms, int joint) {
  const int incoming = skeleton.IncomingBone(joint);
  const RigidTransform& t = incoming >= 0 ? bone_transforms[incoming] : pose.root;
  return t.Apply(skeleton.joint(joint).rest_position);
}

}  // namespace deform
