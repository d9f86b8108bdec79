// Joint angles from OpenIGTLink receivers: STRING messages holding the project's pose syntax
// ("JOINT:AXIS:DEGREES[,...]", as deformctl and deform-vr take it, e.g. "knee:flexion:90" or
// "joint1:x:45,joint2:x:-10"), or "rest". The bridge keeps one angle per joint and axis: a message
// sets the angles it names and leaves the others as they were; "rest" clears them all.
//
// Not thread-safe: the bridge serializes calls.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "deform/v1/deform.pb.h"

namespace deform::igtl_bridge {

class JointAngleInput {
 public:
  explicit JointAngleInput(deform::v1::MeshSummary summary) : summary_(std::move(summary)) {}

  // Applies `text`. False, with `error` set and nothing changed, when the text is malformed or
  // names a joint or axis the mesh's skeleton does not have.
  bool Apply(const std::string& text, std::string* error);

  // The current angles as a pose (sequence and timestamp left 0); no angles at rest.
  deform::v1::PoseUpdate Pose() const;

 private:
  struct Term {
    std::string joint;  // the joint's name
    std::string axis;
    double degrees = 0;
  };
  // The joint `joint` (a name or 0-based index) names, or nullptr.
  const deform::v1::JointInfo* FindJoint(const std::string& joint) const;

  deform::v1::MeshSummary summary_;
  std::vector<Term> terms_;  // in the order first set
};

}  // namespace deform::igtl_bridge
