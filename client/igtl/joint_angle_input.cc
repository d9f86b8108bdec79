#include "igtl/joint_angle_input.h"

#include "core/base/text.h"
#include "lib/deform_client.h"

namespace deform::igtl_bridge {

const deform::v1::JointInfo* JointAngleInput::FindJoint(const std::string& joint) const {
  for (const deform::v1::JointInfo& info : summary_.joints()) {
    if (info.name() == joint) return &info;
  }
  int index = -1;
  if (ParseInt(joint, &index) && index >= 0 && index < summary_.joints_size()) {
    return &summary_.joints(index);
  }
  return nullptr;
}

bool JointAngleInput::Apply(const std::string& text, std::string* error) {
  const std::string_view trimmed = Trim(text);
  if (trimmed == "rest") {
    terms_.clear();
    return true;
  }
  deform::v1::PoseUpdate parsed;
  if (trimmed.empty()) {
    *error = "no joint angles: expected JOINT:AXIS:DEGREES[,...] or rest";
    return false;
  }
  if (!client::ParsePoseAngles(std::string(trimmed), &parsed, error)) return false;
  std::vector<Term> updated = terms_;
  for (const deform::v1::JointAngle& angle : parsed.angles()) {
    const deform::v1::JointInfo* joint = FindJoint(angle.joint());
    if (joint == nullptr) {
      *error = "no joint '" + angle.joint() + "' in the mesh's skeleton";
      return false;
    }
    bool axis_known = angle.axis() == "x" || angle.axis() == "y" || angle.axis() == "z";
    for (const deform::v1::DegreeOfFreedom& dof : joint->dofs()) {
      axis_known = axis_known || dof.name() == angle.axis();
    }
    if (!axis_known) {
      *error = "joint '" + joint->name() + "' has no axis '" + angle.axis() +
               "' (x, y, z or one of its degrees of freedom)";
      return false;
    }
    bool replaced = false;
    for (Term& term : updated) {
      if (term.joint == joint->name() && term.axis == angle.axis()) {
        term.degrees = angle.degrees();
        replaced = true;
      }
    }
    if (!replaced) updated.push_back({joint->name(), angle.axis(), angle.degrees()});
  }
  terms_ = std::move(updated);
  return true;
}

deform::v1::PoseUpdate JointAngleInput::Pose() const {
  deform::v1::PoseUpdate pose;
  for (const Term& term : terms_) {
    deform::v1::JointAngle* angle = pose.add_angles();
    angle->set_joint(term.joint);
    angle->set_axis(term.axis);
    angle->set_degrees(term.degrees);
  }
  return pose;
}

}  // namespace deform::igtl_bridge
