// One received frame measured against the local model: the method's quality (volume change,
// clearance, rigid-zone error) and linear blend skinning's for the same pose with the model's own
// weights, the reference the method is compared with (core/eval/quality.h, skinning.h).
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/model/deformation_model.h"

namespace deform::animation {

struct FrameMeasures {
  double volume_change = 0;      // (V - V_rest) / V_rest of the frame
  double lbs_volume_change = 0;  // the same for LBS of the pose
  double clearance_min = 0;      // smallest skin-to-bone distance ratio (posed over rest)
  double clearance_p01 = 0;
  double lbs_clearance_min = 0;
  double lbs_clearance_p01 = 0;
  // Largest distance of a rigid-zone vertex from LBS of the same pose, over the rest diagonal.
  double rigid_zone_error = 0;
};

// Measures frames on one model. Keeps its buffers between frames.
class FrameMeter {
 public:
  explicit FrameMeter(const DeformationModel& model) : model_(model) {}

  // `posed`: the frame's positions in the model's vertex order (VertexOrder::ToModelOrder).
  FrameMeasures Measure(const Positions& posed, const Pose& pose);

 private:
  const DeformationModel& model_;
  std::vector<RigidTransform> bones_;
  Positions skinned_;
};

}  // namespace deform::animation
