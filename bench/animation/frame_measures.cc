#include "animation/frame_measures.h"

#include "core/eval/quality.h"
#include "core/eval/skinning.h"

namespace deform::animation {

FrameMeasures FrameMeter::Measure(const Positions& posed, const Pose& pose) {
  ForwardKinematics(model_.skeleton(), pose, &bones_);
  LinearBlendSkinning(model_.mesh().vertices, model_.bone_weights(), bones_, &skinned_);
  const QualityReport method = MeasureQuality(model_.mesh(), posed, model_.skeleton(), bones_,
                                              skinned_, model_.rigid_bones());
  const QualityReport lbs = MeasureQuality(model_.mesh(), skinned_, model_.skeleton(), bones_,
                                           skinned_, model_.rigid_bones());
  FrameMeasures measures;
  measures.volume_change = method.volume_change;
  measures.lbs_volume_change = lbs.volume_change;
  measures.clearance_min = method.clearance.min;
  measures.clearance_p01 = method.clearance.p01;
  measures.lbs_clearance_min = lbs.clearance.min;
  measures.lbs_clearance_p01 = lbs.clearance.p01;
  measures.rigid_zone_error = method.rigid_zone_error;
  return measures;
}

}  // namespace deform::animation
