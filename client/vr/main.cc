// deform-vr: the VR front end's stand-in. Loads a mesh, streams joint poses at headset rate and
// reports what a headset would see: pose-to-frame latency, skipped frames, server solve time.
//
//   deform-vr [--target ADDR] [--mesh FILE --skeleton FILE | --mesh-id ID] [--rate HZ]
//             [--duration S] [--cycle-seconds S] [--joint J --axis A] [--json]
//   deform-vr [--target ADDR] [--mesh FILE --skeleton FILE] --pose SPEC [--frames 1] --out FILE
//
// Exit codes: 0 success, 1 runtime or server error (one line on stderr naming the gRPC status
// code), 2 usage error.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "cli/command_line.h"
#include "cli/frame_encoding_flag.h"
#include "cli/mesh_source.h"
#include "core/io/mesh_io.h"
#include "lib/deform_client.h"
#include "lib/flexion_trajectory.h"
#include "lib/joint_choice.h"
#include "vr/frame_mesh.h"
#include "vr/pose_player.h"
#include "vr/vr_report.h"

namespace {

using deform::client::JointAxis;

constexpr char kProgram[] = "deform-vr";

struct VrArgs {
  deform::cli::ConnectionArgs connection;
  deform::cli::MeshSource source;
  std::string joint;
  std::string axis;
  double rate_hz = 90.0;
  deform::v1::FrameEncoding encoding = deform::v1::FRAME_ENCODING_FLOAT32;
  double duration_s = 4.0;
  double cycle_s = 2.0;
  double peak_degrees = 120.0;
  std::string pose_spec;
  deform::v1::PoseUpdate scripted_pose;  // parsed from pose_spec
  int frames = 0;                        // 0: duration * rate, or 1 with --pose
  std::string out_path;
  bool unload = false;
  bool keep_mesh = false;
  bool json = false;
  int answer_timeout_ms = 5000;
};

int Fail(const grpc::Status& status) { return deform::cli::ReportFailure(kProgram, status); }

int Fail(const deform::Status& status) {
  std::cerr << kProgram << ": " << status.ToString() << "\n";
  return 1;
}

int PosesToSend(const VrArgs& args) {
  if (args.frames > 0) return args.frames;
  if (!args.pose_spec.empty()) return 1;
  return std::max(1, static_cast<int>(std::lround(args.duration_s * args.rate_hz)));
}

deform::vr::PoseGenerator MakePoseGenerator(const VrArgs& args, const JointAxis& knee) {
  if (!args.pose_spec.empty()) {
    return [pose = args.scripted_pose](int) { return pose; };
  }
  return [knee, rate = args.rate_hz, cycle = args.cycle_s, peak = args.peak_degrees](int k) {
    deform::v1::PoseUpdate pose;
    deform::v1::JointAngle* angle = pose.add_angles();
    angle->set_joint(knee.joint);
    angle->set_axis(knee.axis);
    angle->set_degrees(deform::client::FlexionDegreesAt(k / rate, cycle, peak));
    return pose;
  };
}

// Writes the last frame's positions with the mesh's triangles to `path`.
int WriteLastFrame(deform::client::DeformClient& client, const std::string& mesh_id,
                   const deform::vr::PlaybackResult& result, const std::string& path) {
  if (!result.last_pose_answered) {
    return Fail(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "the last pose got no frame"));
  }
  deform::v1::GetMeshInfoResponse geometry;
  const grpc::Status fetched = client.GetMeshInfo(mesh_id, /*include_geometry=*/true, &geometry);
  if (!fetched.ok()) return Fail(fetched);
  auto mesh = deform::vr::MeshFromBuffers(result.last_frame.positions(), geometry.triangles());
  if (!mesh.ok()) return Fail(mesh.status());
  const deform::Status written = deform::WriteMeshFile(*mesh, path);
  if (!written.ok()) return Fail(written);
  return 0;
}

int RunOnMesh(deform::client::DeformClient& client, const VrArgs& args,
              const deform::v1::MeshSummary& summary) {
  const JointAxis knee = deform::client::ChoosePosedJoint(summary, args.joint, args.axis);
  deform::vr::PlaybackSettings settings;
  settings.rate_hz = args.rate_hz;
  settings.poses = PosesToSend(args);
  settings.answer_timeout_ms = args.answer_timeout_ms;
  settings.encoding = args.encoding;
  const deform::vr::PlaybackResult result =
      deform::vr::PlayPoses(client, summary.mesh_id(), settings, MakePoseGenerator(args, knee));
  if (!result.status.ok()) return Fail(result.status);
  if (result.poses_rejected > 0) {
    return Fail(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, result.first_rejection));
  }
  if (!args.out_path.empty()) {
    const int written = WriteLastFrame(client, summary.mesh_id(), result, args.out_path);
    if (written != 0) return written;
  }

  deform::vr::RunDescription run;
  run.mesh_id = summary.mesh_id();
  run.mesh_name = summary.name();
  run.vertices = summary.vertex_count();
  run.triangles = summary.triangle_count();
  run.pose = args.pose_spec;
  run.knee = knee;
  run.peak_degrees = args.peak_degrees;
  run.cycle_s = args.cycle_s;
  run.encoding = deform::cli::FrameEncodingName(args.encoding);
  run.rate_hz = args.rate_hz;
  run.out_path = args.out_path;
  if (args.json) {
    std::cout << deform::vr::ReportJson(run, result).dump() << std::endl;
  } else {
    std::cout << deform::vr::ReportText(run, result) << std::flush;
  }
  return 0;
}

int Run(const VrArgs& args) {
  return deform::cli::RunOnAcquiredMesh(
      kProgram, args.connection, args.source,
      [&](deform::client::DeformClient& client, const deform::v1::MeshSummary& summary) {
        return RunOnMesh(client, args, summary);
      },
      [&](bool loaded) { return args.unload || (loaded && !args.keep_mesh); });
}

void AddFlags(CLI::App& app, VrArgs& args) {
  deform::cli::AddConnectionFlags(app, &args.connection);
  const deform::cli::MeshSourceOptions source = deform::cli::AddMeshSourceFlags(app, &args.source);
  CLI::Option* mesh_id = app.add_option("--mesh-id", args.source.mesh_id,
                                        "Use a mesh the server already holds (not unloaded at the "
                                        "end unless --unload)");
  mesh_id->excludes(source.mesh)->excludes(source.skeleton)->excludes(source.phantom_vertices);
  source.rotation_blend->excludes(mesh_id);

  app.add_option("--joint", args.joint,
                 "Joint the trajectory bends, name or 0-based index (default: knee when the "
                 "skeleton has a knee with a flexion dof, else 1)");
  app.add_option("--axis", args.axis,
                 "Axis of the bend: a dof name or x|y|z (default: flexion for the knee, else x)");
  deform::cli::AddFrameEncodingFlag(app, &args.encoding);
  app.add_option("--rate", args.rate_hz, "Poses per second")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 100000.0));
  app.add_option("--duration", args.duration_s, "Seconds of trajectory to play")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--cycle-seconds", args.cycle_s,
                 "Length of one flexion cycle: rest -> peak -> rest along a cosine")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--peak-degrees", args.peak_degrees, "Flexion at the middle of each cycle")
      ->capture_default_str();

  CLI::Option* pose = app.add_option(
      "--pose", args.pose_spec,
      "Scripted mode: send this pose instead of the trajectory, JOINT:AXIS:DEGREES[,...] "
      "(e.g. knee:flexion:90 or 1:x:90)");
  app.add_option("--frames", args.frames, "Poses to send (default: duration x rate; 1 with --pose)")
      ->check(CLI::Range(1, 100000000));
  app.add_option("--out", args.out_path,
                 "Write the mesh deformed by the last pose (format from the extension)");
  pose->excludes("--joint")->excludes("--axis");

  CLI::Option* unload = app.add_flag("--unload", args.unload,
                                     "Unload the mesh at the end, even one given by --mesh-id");
  app.add_flag("--keep-mesh", args.keep_mesh, "Leave a mesh this run loaded on the server")
      ->excludes(unload);
  app.add_flag("--json", args.json, "Print one JSON object instead of text");
  app.add_option("--answer-timeout-ms", args.answer_timeout_ms,
                 "After the last send: how long to wait for its frame, then for the stream's end")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "deform-vr: stands in for a VR front end. Loads a mesh (default: the built-in knee "
      "phantom), streams a knee flexion trajectory rest -> 120 degrees -> rest (one cycle per "
      "--cycle-seconds) at --rate Hz for --duration seconds on a fixed schedule (pose k at "
      "t0 + k / rate), and reports pose-to-frame latency (p50, p99, max), frames sent, received "
      "and "
      "skipped, and the server's median solve time. With --pose it sends that pose instead and "
      "--out writes the deformed mesh. The mesh it loads is unloaded at the end."};
  app.get_formatter()->column_width(34);
  VrArgs args;
  AddFlags(app, args);
  if (const auto exit_code = deform::cli::ParseCommandLine(app, argc, argv, kProgram)) {
    return *exit_code;
  }
  if (!args.out_path.empty()) {
    const auto format = deform::MeshFormatFromPath(args.out_path);
    if (!format.ok()) {
      std::cerr << kProgram << ": " << format.status().ToString() << "\n";
      return 2;
    }
  }
  if (!args.pose_spec.empty()) {
    std::string error;
    if (!deform::client::ParsePoseAngles(args.pose_spec, &args.scripted_pose, &error)) {
      std::cerr << kProgram << ": " << error << "\n";
      return 2;
    }
  }
  return Run(args);
}
