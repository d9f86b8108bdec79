#include "vr/joint_choice.h"

namespace deform::vr {
namespace {

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

JointAxis ChooseKneeAxis(const deform::v1::MeshSummary& summary, const std::string& joint,
                         const std::string& axis) {
  JointAxis choice = HasKneeFlexion(summary) ? JointAxis{"knee", "flexion"} : JointAxis{"1", "x"};
  if (!joint.empty()) choice.joint = joint;
  if (!axis.empty()) choice.axis = axis;
  return choice;
}

}  // namespace deform::vr
