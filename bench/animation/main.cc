// deform-animation-bench: streams a whole multi-joint animation through a running deformd, one pose
// at a time, and measures every frame it gets back against the same model built locally: volume
// change and skin-to-bone clearance beside linear blend skinning's for the same pose, the largest
// distance of rigid-zone vertices from that LBS, and the round-trip latency.
//
//   deform-animation-bench [--target ADDR] [--phantom-vertices N | --mesh FILE --skeleton FILE
//                          [--weights FILE] | --mesh RIG.glb] [--rotation-blend quaternion|linear]
//                          (--poses FILE | --animation NAME|INDEX [--fps F]) [--json]
//
// --animation plays the glTF rig's own animation (--mesh RIG.glb), sampled at F frames a second
// (default 30) over its duration, instead of a pose file.
//
// Exit codes: 0 success, 1 runtime or server error (one line on stderr), 2 usage error (a bad
// flag, an unreadable or malformed animation, naming the line).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <string>
#include <vector>

#include "animation/animation_pose.h"
#include "animation/animation_report.h"
#include "animation/animation_script.h"
#include "animation/frame_measures.h"
#include "animation/lockstep_stream.h"
#include "animation/played_frames.h"
#include "animation/reference_check.h"
#include "animation/vertex_order.h"
#include "cli/command_line.h"
#include "cli/mesh_source.h"
#include "cli/rotation_blend_flag.h"
#include "core/constraints/bone_reach.h"
#include "core/io/model_input.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"

namespace {

using deform::Status;
using deform::animation::PlayedFrame;

constexpr char kProgram[] = "deform-animation-bench";

struct BenchArgs {
  deform::cli::ConnectionArgs connection;
  deform::cli::MeshSource source;
  std::string poses_path;
  std::string animation;  // a glTF animation's name or index (instead of poses_path)
  double fps = 30;
  bool json = false;
  int frame_timeout_ms = 30'000;
};

int Fail(const Status& status, int exit_code = 1) {
  std::cerr << kProgram << ": " << status.ToString() << "\n";
  return exit_code;
}

int Fail(const grpc::Status& status) { return deform::cli::ReportFailure(kProgram, status); }

// The local reference: the inputs read as the server reads them, the model built with the options
// the server derives from the same MethodOptions (ModelOptions::Paper() plus the rotation blend).
struct Reference {
  deform::ModelInput input;
  std::shared_ptr<const deform::DeformationModel> model;
  double build_ms = 0;
};

deform::StatusOr<Reference> BuildReference(const deform::cli::MeshSource& source) {
  Reference reference;
  const int phantom_vertices =
      source.phantom_vertices == 0 ? deform::kDefaultPhantomVertices : source.phantom_vertices;
  DEFORM_ASSIGN_OR_RETURN(reference.input,
                          deform::LoadModelInput(source.mesh_path, source.skeleton_path,
                                                 source.weights_path, phantom_vertices));
  return reference;
}

deform::ModelOptions ReferenceOptions(deform::v1::RotationBlend blend) {
  deform::ModelOptions options = deform::ModelOptions::Paper();
  options.rotation_blend = blend == deform::v1::ROTATION_BLEND_LINEAR
                               ? deform::RotationBlend::kLinear
                               : deform::RotationBlend::kQuaternion;
  return options;
}

int RunOnMesh(deform::client::DeformClient& client, const BenchArgs& args,
              const Reference& reference, const std::vector<PlayedFrame>& frames,
              const std::string& animation, const deform::v1::MeshSummary& summary) {
  const deform::DeformationModel& model = *reference.model;
  auto order = deform::animation::VertexOrder::Create(reference.input.file_vertex_to_mesh,
                                                      model.mesh().num_vertices());
  if (!order.ok()) return Fail(order.status());
  const grpc::Status consistent =
      deform::animation::CheckServerMatchesReference(client, summary, model, *order);
  if (!consistent.ok()) return Fail(consistent);

  std::vector<deform::animation::FrameRecord> records;
  records.reserve(frames.size());
  deform::animation::FrameMeter meter(model);
  deform::Positions posed;
  {
    deform::animation::LockstepStream stream(client, summary.mesh_id());
    for (std::size_t k = 0; k < frames.size(); ++k) {
      deform::animation::AnsweredPose answer;
      const grpc::Status exchanged =
          stream.Exchange(frames[k].update, args.frame_timeout_ms, &answer);
      if (!exchanged.ok()) {
        const std::string where = animation.empty()
                                      ? "line " + std::to_string(frames[k].line)
                                      : "time " + std::to_string(frames[k].time_s) + " s";
        return Fail(grpc::Status(
            exchanged.error_code(),
            "frame " + std::to_string(k) + " (" + where + "): " + exchanged.error_message()));
      }
      const Status decoded = order->ToModelOrder(answer.frame.positions(), &posed);
      if (!decoded.ok()) return Fail(decoded);
      deform::animation::FrameRecord record;
      record.frame = static_cast<int>(k);
      record.line = frames[k].line;
      record.time_s = frames[k].time_s;
      record.measures = meter.Measure(posed, frames[k].pose);
      record.round_trip_ms = answer.round_trip_ms;
      record.server_solve_ms = answer.frame.timings().rhs_ms() + answer.frame.timings().solve_ms();
      record.clamped_angles = static_cast<int>(answer.frame.clamped_angles());
      records.push_back(record);
    }
    const grpc::Status finished = stream.Finish(args.frame_timeout_ms);
    if (!finished.ok()) return Fail(finished);
  }

  deform::animation::RunHeader header;
  header.mesh = reference.input.description;
  header.mesh_id = summary.mesh_id();
  header.rotation_blend = deform::cli::RotationBlendName(summary.rotation_blend());
  header.binding = model.weights_given() ? "given weights" : "through the body";
  header.frame_vertices = order->frame_vertices();
  header.solved_vertices = model.mesh().num_vertices();
  for (int bone : model.rigid_bones()) header.rigid_vertices += bone >= 0 ? 1 : 0;
  header.local_build_ms = reference.build_ms;
  header.animation = animation;
  if (args.json) {
    std::cout << deform::animation::ReportJson(header, records).dump() << std::endl;
  } else {
    std::cout << deform::animation::ReportText(header, records) << std::flush;
  }
  return 0;
}

void AddFlags(CLI::App& app, BenchArgs& args) {
  deform::cli::AddConnectionFlags(app, &args.connection);
  deform::cli::AddMeshSourceFlags(app, &args.source);
  CLI::Option* poses = app.add_option(
      "--poses", args.poses_path,
      "Animation file: one frame per line, JOINT:AXIS:DEG[,...] optionally followed by "
      ";root=TX,TY,TZ,AX,AY,AZ,DEG (root translation, then a rotation of DEG degrees "
      "about the axis AX,AY,AZ); blank lines and # comments ignored");
  CLI::Option* animation =
      app.add_option("--animation", args.animation,
                     "Play the glTF rig's own animation (--mesh RIG.glb): its name, or its index "
                     "from 0, in the file's animations")
          ->excludes(poses);
  app.add_option("--fps", args.fps, "Frames a second at which --animation is sampled")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->needs(animation);

  app.add_flag("--json", args.json, "Print one JSON object (per-frame arrays and a summary)");
  app.add_option("--frame-timeout-ms", args.frame_timeout_ms, "How long to wait for each frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  CLI::App app{
      "deform-animation-bench: streams an animation (one pose per line of --poses, or a glTF "
      "rig's own --animation) through "
      "deformd one pose at a time and measures every frame against the same model built "
      "locally: volume change and skin-to-bone clearance beside linear blend skinning's (same "
      "pose, the model's weights), the rigid zones' distance from that LBS, and the round-trip "
      "latency; per frame and in summary (median, worst, the five worst frames)."};
  app.get_formatter()->column_width(34);
  BenchArgs args;
  AddFlags(app, args);
  if (const auto exit_code = deform::cli::ParseCommandLine(app, argc, argv, kProgram)) {
    return *exit_code;
  }
  if (args.poses_path.empty() == args.animation.empty()) {
    std::cerr << kProgram << ": give --poses FILE or --animation NAME|INDEX\n";
    return 2;
  }
  if (!args.animation.empty() && !deform::IsGltfPath(args.source.mesh_path)) {
    std::cerr << kProgram
              << ": --animation plays a glTF rig's own animation: give --mesh RIG.glb\n";
    return 2;
  }

  auto reference = BuildReference(args.source);
  if (!reference.ok()) return Fail(reference.status());
  std::string animation;
  auto frames =
      args.animation.empty()
          ? deform::animation::FramesFromPoseFile(args.poses_path, reference->input.skeleton)
          : deform::animation::FramesFromGltfAnimation(args.source.mesh_path,
                                                       reference->input.skeleton, args.animation,
                                                       args.fps, &animation);
  if (!frames.ok()) return Fail(frames.status(), 2);
  const auto build_start = std::chrono::steady_clock::now();
  // As the server builds a limb with bones (its default constraints).
  deform::ModelOptions options = ReferenceOptions(args.source.rotation_blend);
  const deform::Status unanchored =
      deform::UnanchorReachedSkin(reference->input.mesh, reference->input.skeleton,
                                  reference->input.bones, deform::ConstraintOptions{}, &options);
  if (!unanchored.ok()) return Fail(unanchored.WithContext("local reference model"));
  auto model = deform::DeformationModel::Build(
      reference->input.mesh, reference->input.skeleton, options,
      reference->input.weights.has_value() ? &*reference->input.weights : nullptr);
  if (!model.ok()) return Fail(model.status().WithContext("local reference model"));
  reference->model = std::move(*model);
  reference->build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - build_start)
          .count();

  return deform::cli::RunOnAcquiredMesh(
      kProgram, args.connection, args.source,
      [&](deform::client::DeformClient& client, const deform::v1::MeshSummary& summary) {
        return RunOnMesh(client, args, *reference, *frames, animation, summary);
      },
      [](bool loaded) { return loaded; });
}
