// libFuzzer target: a Deform stream's pose as the server converts it. The bytes are a serialized
// deform.v1.PoseUpdate (as received); PoseInputFromProto checks and resolves it against the knee
// phantom's skeleton and PoseFromInput makes the core pose; ToolsFromProto checks its tools
// against the phantom's box. Rejections are Statuses; an accepted pose must have finite unit
// rotations and a finite root, and accepted tools a radius in (0, kMaxToolRadius diagonals].
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "deform/v1/deform.pb.h"
#include "service/deform/pose_input.h"
#include "tests/fuzz/fuzz_model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const deform::DeformationModel& model = deform::fuzz::PhantomModel();
  deform::v1::PoseUpdate update;
  if (!update.ParseFromArray(data, static_cast<int>(size))) return 0;
  deform::service::PoseInput input;
  if (!deform::service::PoseInputFromProto(update, model.skeleton(), &input).ok()) return 0;
  deform::Pose pose;
  if (!deform::service::PoseFromInput(model.skeleton(), input, &pose).ok()) return 0;
  for (const auto& q : pose.joint_rotations) {
    if (!q.coeffs().allFinite() || std::abs(q.norm() - 1) > 1e-6) __builtin_trap();
  }
  if (!pose.root.translation.allFinite()) __builtin_trap();
  const Eigen::Vector3d lower = model.mesh().vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d upper = model.mesh().vertices.colwise().maxCoeff().transpose();
  if (!deform::service::ToolsFromProto(update, lower, upper, &input.tools).ok()) return 0;
  if (input.tools.count > deform::ToolSet::kMaxTools) __builtin_trap();
  for (int t = 0; t < input.tools.count; ++t) {
    const deform::Tool& tool = input.tools.tools[t];
    if (!tool.a.allFinite() || !tool.b.allFinite() || !(tool.radius > 0) ||
        tool.radius > deform::kMaxToolRadius * (upper - lower).norm()) {
      __builtin_trap();
    }
  }
  return 0;
}
