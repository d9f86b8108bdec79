#include "joint_choice.h"

namespace deform::client {
namespace {

bool Names(const deform::v1::JointInfo& joint, const std::string& name_or_index) {
  return joint.name() == name_or_index || std::to_string(joint.index()) == name_or_index;
}

bool HasKneeFlexion(const deform::v1::MeshSummary& summary) {
  for (const auto& joint : summary.joints()) {
    if (joint.name() != "knee") continue;
    for (const auto& dof : joint.dofs()) {
      if (dof.name() == "flexion") return true;
    }
  }
  return false;
}

}  // namespace

JointAxis ChoosePosedJoint(const deform::v1::MeshSummary& summary, const std::string& joint,
                           const std::string& axis) {
  JointAxis choice = HasKneeFlexion(summary) ? JointAxis{"knee", "flexion"} : JointAxis{"1", "x"};
  if (!joint.empty()) choice.joint = joint;
  if (!axis.empty()) choice.axis = axis;
  return choice;
}

std::string ChooseRegionJoint(const deform::v1::MeshSummary& summary,
                              const std::string& preferred) {
  for (const auto& joint : summary.joints()) {
    if (joint.has_region() && Names(joint, preferred)) return joint.name();
  }
  for (const auto& joint : summary.joints()) {
    if (joint.has_region()) return joint.name();
  }
  return {};
}

}  // namespace deform::client
