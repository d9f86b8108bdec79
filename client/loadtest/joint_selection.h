// Which joints the load test poses and stiffens, read off the loaded mesh's summary.
#pragma once

#include <string>

#include "deform/v1/deform.pb.h"

namespace deform::loadtest {

struct JointAxis {
  std::string joint;  // a joint name or 0-based index, as JointAngle.joint
  std::string axis;   // a degree of freedom's name or "x", "y", "z", as JointAngle.axis
};

// knee:flexion when the skeleton has a joint "knee" with a "flexion" degree of freedom (the
// built-in phantom), otherwise 1:x (the knee of the shared TGF legs). Non-empty `joint` / `axis`
// override the choice.
JointAxis ChoosePosedJoint(const deform::v1::MeshSummary& summary, const std::string& joint,
                           const std::string& axis);

// The name of the inner joint (JointInfo.has_region) whose material the stiffness updates change:
// `preferred` (a name or 0-based index) when it has a region, else the first joint that has one.
// Empty when no joint has a region.
std::string ChooseRegionJoint(const deform::v1::MeshSummary& summary, const std::string& preferred);

}  // namespace deform::loadtest
