// Which joints the clients pose and stiffen when the command line does not say, read off the
// loaded mesh's summary.
#pragma once

#include <string>

#include "deform/v1/deform.pb.h"

namespace deform::client {

struct JointAxis {
  std::string joint;  // a joint name or 0-based index, as JointAngle.joint
  std::string axis;   // a degree of freedom's name or "x", "y", "z", as JointAngle.axis
};

// The joint and axis the flexion bends: knee:flexion when the mesh's skeleton has a joint named
// "knee" with a degree of freedom named "flexion" (the built-in phantom); otherwise 1:x, the second
// joint bent about the rest-frame x axis (the knee of the shared leg's TGF skeleton). Non-empty
// `joint` / `axis` override the choice.
JointAxis ChoosePosedJoint(const deform::v1::MeshSummary& summary, const std::string& joint,
                           const std::string& axis);

// The name of the inner joint (JointInfo.has_region) whose material stiffness updates change:
// `preferred` (a name or 0-based index) when it has a region, else the first joint that has one.
// Empty when no joint has a region.
std::string ChooseRegionJoint(const deform::v1::MeshSummary& summary, const std::string& preferred);

}  // namespace deform::client
