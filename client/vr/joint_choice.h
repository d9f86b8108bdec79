// Which joint and axis the VR stand-in bends when the command line does not say.
#pragma once

#include <string>

#include "deform/v1/deform.pb.h"

namespace deform::vr {

struct JointAxis {
  std::string joint;  // a joint name or 0-based index, as JointAngle.joint
  std::string axis;   // a degree of freedom's name or "x", "y", "z", as JointAngle.axis
};

// knee:flexion when the mesh's skeleton has a joint named "knee" with a degree of freedom named
// "flexion" (the built-in phantom); otherwise 1:x, the second joint bent about the rest-frame x
// axis (the knee of the shared leg's TGF skeleton). Non-empty `joint` / `axis` override the choice.
JointAxis ChooseKneeAxis(const deform::v1::MeshSummary& summary, const std::string& joint,
                         const std::string& axis);

}  // namespace deform::vr
