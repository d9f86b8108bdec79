// deform-loadtest: many concurrent Deform streams at headset rate against one server.
//
//   deform-loadtest [--target ADDR] [--mesh FILE --skeleton FILE | --mesh-id ID] [--streams N]
//                   [--rate HZ] [--reconnect]
//                   [--duration S] [--warmup S] [--stiffness-every S] [--joint J --axis A]
//                   [--json] [--fail-on-errors]
//
// Loads the mesh once, runs the streams, prints the results and unloads the mesh. Exit codes: 0
// when the run completed (errors are counted in the report), 1 when it could not run (connect or
// load failure) or, with --fail-on-errors, when errors were counted, 2 for usage errors.
#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <string>

#include "cli/command_line.h"
#include "cli/frame_encoding_flag.h"
#include "cli/mesh_source.h"
#include "cli/rotation_blend_flag.h"
#include "lib/deform_client.h"
#include "lib/joint_choice.h"
#include "loadtest/load_plan.h"
#include "loadtest/load_report.h"
#include "loadtest/load_runner.h"

namespace {

constexpr char kProgram[] = "deform-loadtest";

// The two soft weights the stiffness updates alternate between (the default soft weight is 1).
constexpr double kSoftWeights[] = {0.5, 1.0};

struct LoadtestArgs {
  deform::cli::ConnectionArgs connection;
  deform::cli::MeshSource source;
  int streams = 1;
  double rate_hz = 90.0;
  double duration_s = 10.0;
  double warmup_s = 1.0;
  double stiffness_every_s = 0.0;
  std::string joint;
  std::string axis;
  double peak_degrees = 120.0;
  double cycle_s = 2.0;
  double drain_s = 2.0;
  deform::v1::FrameEncoding encoding = deform::v1::FRAME_ENCODING_FLOAT32;
  bool keep_mesh = false;
  bool reconnect = false;
  bool json = false;
  bool fail_on_errors = false;
};

// Keeps freed heap memory mapped for reuse. The load test receives every stream's frames on gRPC's
// threads (12 bytes a vertex in float32: tens of KB to megabytes each) and frees them soon after;
// by default glibc hands the free top of a thread's heap back to the kernel once it exceeds the
// trim threshold (128 KiB to start with), so the next frames' buffers fault their pages in again.
// Fixing the trim threshold stops glibc adapting its mmap threshold too, which is therefore raised
// as well, so that a large mesh's frames are not fresh mappings each time. The page faults it
// saves: bench/RESULTS.md, "Frame encodings, transport and the load test".
void KeepFreedHeapMapped() {
#if defined(__GLIBC__)
  constexpr int kTrimThresholdBytes = 64 << 20;
  constexpr int kMmapThresholdBytes = 32 << 20;  // glibc's upper limit on 64-bit
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
  mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes);
#endif
}

int Fail(const grpc::Status& status) { return deform::cli::ReportFailure(kProgram, status); }

// Runs the plan on a loaded mesh and prints the report; returns the exit code.
int RunOnMesh(deform::client::DeformClient& client, const LoadtestArgs& args,
              const deform::v1::MeshSummary& summary, double acquire_ms) {
  deform::loadtest::LoadPlan plan;
  plan.mesh_id = summary.mesh_id();
  plan.vertex_count = summary.vertex_count();
  plan.streams = args.streams;
  plan.rate_hz = args.rate_hz;
  plan.warmup_s = args.warmup_s;
  plan.duration_s = args.duration_s;
  plan.posed = deform::client::ChoosePosedJoint(summary, args.joint, args.axis);
  plan.peak_degrees = args.peak_degrees;
  plan.cycle_s = args.cycle_s;
  plan.drain_s = args.drain_s;
  plan.encoding = args.encoding;
  plan.reconnect = args.reconnect;

  deform::loadtest::RunDescription run;
  run.target = args.connection.target;
  run.mesh = args.source.Description();
  run.mesh_id = summary.mesh_id();
  run.acquire_ms = acquire_ms;
  run.vertices = summary.vertex_count();
  run.triangles = summary.triangle_count();
  run.rotation_blend = deform::cli::RotationBlendName(summary.rotation_blend());
  run.encoding = deform::cli::FrameEncodingName(args.encoding);
  if (args.stiffness_every_s > 0) {
    run.stiffness_joint = deform::client::ChooseRegionJoint(summary, plan.posed.joint);
    if (run.stiffness_joint.empty()) {
      return Fail(grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                               "--stiffness-every needs an inner joint (has_region); the mesh "
                               "has none"));
    }
    plan.stiffness_every_s = args.stiffness_every_s;
    for (double soft : kSoftWeights) {
      plan.stiffness_updates.push_back(
          deform::loadtest::SoftWeightUpdate(run.stiffness_joint, soft));
    }
  }

  deform::loadtest::RunOutcome outcome = deform::loadtest::RunLoad(client, plan);
  const deform::loadtest::LoadReport report = deform::loadtest::BuildReport(run, plan, &outcome);
  if (args.json) {
    std::cout << deform::loadtest::ReportJson(report).dump() << std::endl;
  } else {
    std::cout << deform::loadtest::ReportText(report) << std::flush;
  }
  return args.fail_on_errors && report.errors > 0 ? 1 : 0;
}

int Run(const LoadtestArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  return deform::cli::RunOnAcquiredMesh(
      kProgram, args.connection, args.source,
      [&](deform::client::DeformClient& client, const deform::v1::MeshSummary& summary) {
        const double acquire_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        return RunOnMesh(client, args, summary, acquire_ms);
      },
      [&](bool loaded) { return loaded && !args.keep_mesh; });
}

void AddFlags(CLI::App& app, LoadtestArgs& args) {
  deform::cli::AddConnectionFlags(app, &args.connection);
  const deform::cli::MeshSourceOptions source = deform::cli::AddMeshSourceFlags(app, &args.source);
  app.add_option("--mesh-id", args.source.mesh_id,
                 "Run on a mesh the server already holds (it is left loaded)")
      ->excludes(source.mesh)
      ->excludes(source.skeleton)
      ->excludes(source.phantom_vertices);

  deform::cli::AddFrameEncodingFlag(app, &args.encoding);
  app.add_option("--streams", args.streams, "Concurrent Deform streams on the mesh")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  app.add_option("--rate", args.rate_hz,
                 "Poses per second per stream; stream i sends pose k at t0 + (k + i/N) / rate")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 100000.0));
  app.add_option("--duration", args.duration_s, "Measured seconds, after the warm-up")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--warmup", args.warmup_s,
                 "Seconds sent first and left out of the frame, latency and gap statistics")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--stiffness-every", args.stiffness_every_s,
                 "Every S measured seconds, each stream (staggered) sends a stiffness update "
                 "setting an inner joint's soft weight, alternately 0.5 and 1 (0 = never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--joint", args.joint,
                 "Joint the poses bend, name or 0-based index (default: knee when the skeleton "
                 "has a knee with a flexion dof, else 1)");
  app.add_option("--axis", args.axis,
                 "Axis of the bend: a dof name or x|y|z (default: flexion for the knee, else x)");
  app.add_option("--peak-degrees", args.peak_degrees,
                 "Flexion runs 0 -> peak -> 0 along a cosine; streams are spread over the cycle")
      ->capture_default_str();
  app.add_option("--cycle-seconds", args.cycle_s, "Length of one flexion cycle")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--drain", args.drain_s,
                 "After the last send: seconds to wait for the last frames, then for the "
                 "streams to finish")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3600.0));
  app.add_flag("--keep-mesh", args.keep_mesh, "Leave the loaded mesh on the server");
  app.add_flag("--reconnect", args.reconnect,
               "Streams that lose their server (UNAVAILABLE) open again on the same mesh "
               "(the client library's ReconnectPolicy, its defaults); counted as reconnects");
  app.add_flag("--json", args.json,
               "Print one JSON object instead of the summary and latency histogram");
  app.add_flag("--fail-on-errors", args.fail_on_errors,
               "Exit 1 when any error was counted (failed streams, rejected notices, malformed "
               "frames; warm-up included)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "deform-loadtest: loads a mesh once (default: the built-in knee phantom), runs N concurrent "
      "Deform streams sending flexion poses at a fixed rate for a warm-up plus the measured "
      "duration, and reports delivery, pose-to-frame latency percentiles, the largest gap "
      "between a stream's frames, errors by status code, stiffness updates and server timings."};
  app.get_formatter()->column_width(34);
  LoadtestArgs args;
  AddFlags(app, args);
  if (const auto exit_code = deform::cli::ParseCommandLine(app, argc, argv, kProgram)) {
    return *exit_code;
  }
  KeepFreedHeapMapped();
  return Run(args);
}
