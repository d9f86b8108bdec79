// The load test's results: merged over streams, as one JSON object or a readable summary.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "loadtest/latency_stats.h"
#include "loadtest/load_plan.h"
#include "loadtest/load_runner.h"

namespace deform::loadtest {

// What the run was, for the report's header.
struct RunDescription {
  std::string target;
  std::string mesh;  // file path or "phantom"
  std::string mesh_id;
  unsigned vertices = 0;
  unsigned triangles = 0;
  std::string rotation_blend;   // as the server reports the mesh loaded
  std::string encoding;         // the frames' (--encoding)
  std::string stiffness_joint;  // empty without stiffness updates
  // From before connecting to the mesh being ready (connect, then load or look up), client side.
  double acquire_ms = 0;
};

struct LoadReport {
  RunDescription run;
  LoadPlan plan;
  std::uint64_t frames_sent = 0;      // measured poses accepted by SendPose
  std::uint64_t frames_received = 0;  // frames answering them
  std::uint64_t skipped_by_server = 0;
  // Errors over the whole run, warm-up included: streams that ended with a non-OK status (by
  // code), rejected notices (counted as INVALID_ARGUMENT) and frames of the wrong size (DATA_LOSS).
  std::uint64_t errors = 0;
  std::map<std::string, std::uint64_t> errors_by_code;
  std::uint64_t poses_rejected = 0;
  std::uint64_t stiffness_rejected = 0;
  std::uint64_t bad_frames = 0;
  std::uint64_t payload_bytes = 0;  // measured frames' positions as they travelled
  std::string first_stream_error;   // "CODE: message" of the first failed stream
  std::vector<double> latency_ms;   // every measured frame's, ascending
  LatencySummary latency;
  double max_gap_ms = 0;
  std::uint64_t reconnects = 0;  // streams opened again after their server was lost
  std::uint64_t stiffness_sent = 0;
  std::uint64_t stiffness_applied = 0;
  double stiffness_factor_ms_p50 = 0;
  ServerTimings server_p50;     // median of each server timing over measured frames
  ConstraintStats constraints;  // merged over streams
  // Per measured frame: the server's share (queue + rhs + solve + constraints + encode) and the
  // rest of the latency (gRPC, the network and both sides' thread wake-ups).
  LatencySummary server_total;
  LatencySummary outside_server;
  // Over measured frames: the mean frames per pass over the factor their solve was part of, and
  // the fraction solved on several threads (the server's FrameTimings; 1 and 0 from a server
  // that does not report them).
  double batch_frames_mean = 1;
  double split_fraction = 0;
  double send_lag_max_ms = 0;

  double delivered_fraction() const;
  double throughput_fps() const;
};

// Merges the streams' outcomes (consumes their sample buffers).
LoadReport BuildReport(const RunDescription& run, const LoadPlan& plan, RunOutcome* outcome);

nlohmann::ordered_json ReportJson(const LoadReport& report);

// A readable summary with a latency histogram.
std::string ReportText(const LoadReport& report);

}  // namespace deform::loadtest
