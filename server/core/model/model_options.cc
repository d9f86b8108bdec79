#include "core/model/model_options.h"

#include <cmath>
#include <limits>
#include <string>

namespace deform {

const char* LaplacianWeightsName(LaplacianWeights weights) {
  switch (weights) {
    case LaplacianWeights::kUniform:
      return "uniform";
    case LaplacianWeights::kCotangent:
      return "cotangent";
    case LaplacianWeights::kIntrinsicCotangent:
      return "intrinsic";
  }
  return "unknown";
}

StatusOr<LaplacianWeights> LaplacianWeightsFromName(std::string_view name) {
  for (const LaplacianWeights weights : {LaplacianWeights::kUniform, LaplacianWeights::kCotangent,
                                         LaplacianWeights::kIntrinsicCotangent}) {
    if (name == LaplacianWeightsName(weights)) return weights;
  }
  return Status::InvalidArgument("laplacian must be uniform, cotangent or intrinsic, got '" +
                                 std::string(name) + "'");
}

ModelOptions ModelOptions::PlainLaplacian(ModelOptions base) {
  base.use_joint_nodes = false;
  base.uniform_material = true;
  return base;
}

namespace {

// INVALID_ARGUMENT "<name> must be finite and in (0, <max>], got <value>" unless it is.
Status CheckInRange(double value, double max, const char* name) {
  if (!std::isfinite(value) || !(value > 0) || value > max) {
    return Status::InvalidArgument(std::string(name) + " must be finite and in (0, " +
                                   std::to_string(max) + "], got " + std::to_string(value));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateModelOptions(const ModelOptions& options) {
  constexpr double kUnbounded = std::numeric_limits<double>::max();
  DEFORM_RETURN_IF_ERROR(CheckInRange(options.joint_node_weight, kUnbounded, "joint_node_weight"));
  DEFORM_RETURN_IF_ERROR(CheckInRange(options.anchor_weight, kUnbounded, "anchor_weight"));
  if (!(options.anchor_distance_factor >= 0)) {
    return Status::InvalidArgument("anchor_distance_factor must be at least 0, got " +
                                   std::to_string(options.anchor_distance_factor));
  }
  if (!(options.rigid_weight_tolerance >= 0 && options.rigid_weight_tolerance < 0.5)) {
    return Status::InvalidArgument(
        "rigid_weight_tolerance (deformctl --rigid-weight-tolerance) "
        "must be in [0, 0.5), got " +
        std::to_string(options.rigid_weight_tolerance));
  }
  if (!(options.anchor_min_fraction >= 0 && options.anchor_min_fraction <= 1)) {
    return Status::InvalidArgument("anchor_min_fraction must be in [0, 1], got " +
                                   std::to_string(options.anchor_min_fraction));
  }
  DEFORM_RETURN_IF_ERROR(CheckInRange(options.joint_node_balance,
                                      ModelOptions::kMaxJointNodeBalance, "joint_node_balance"));
  if (options.linear_blend_segments < 1 ||
      options.linear_blend_segments > ModelOptions::kMaxLinearBlendSegments) {
    return Status::InvalidArgument("linear_blend_segments must be in [1, " +
                                   std::to_string(ModelOptions::kMaxLinearBlendSegments) +
                                   "], got " + std::to_string(options.linear_blend_segments));
  }
  return Status::Ok();
}

}  // namespace deform
