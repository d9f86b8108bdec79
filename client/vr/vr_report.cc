#include "vr/vr_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace deform::vr {
namespace {

// Nearest-rank percentile (q in [0, 1]) of unsorted values; 0 for none.
double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const double rank = std::ceil(q * static_cast<double>(values.size()));
  const std::size_t index = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
  const auto nth = values.begin() + static_cast<std::ptrdiff_t>(index);
  std::nth_element(values.begin(), nth, values.end());
  return *nth;
}

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

double Round3(double value) { return std::round(value * 1e3) / 1e3; }

// Poses that got neither a frame nor a rejection. The server's skipped_poses count a subset of
// them; the rest were replaced in the client's send queue or lost when the stream ended.
int FramesSkipped(const PlaybackResult& result) {
  return std::max(static_cast<int>(result.skipped_by_server), result.PosesUnanswered());
}

}  // namespace

namespace {

// Mean bytes of a frame's positions as they travelled.
double BytesPerFrame(const PlaybackResult& result) {
  return static_cast<double>(result.payload_bytes) / std::max(result.frames_received, 1);
}

}  // namespace

nlohmann::ordered_json ReportJson(const RunDescription& run, const PlaybackResult& result) {
  nlohmann::ordered_json out;
  out["mesh_id"] = run.mesh_id;
  out["mesh"] = run.mesh_name;
  out["vertices"] = run.vertices;
  out["triangles"] = run.triangles;
  if (run.pose.empty()) {
    out["trajectory"] = run.knee.joint + ":" + run.knee.axis;
    out["peak_degrees"] = run.peak_degrees;
    out["cycle_s"] = run.cycle_s;
  } else {
    out["pose"] = run.pose;
  }
  out["rate_hz"] = run.rate_hz;
  out["frames_sent"] = result.poses_sent;
  out["frames_received"] = result.frames_received;
  out["frames_skipped"] = FramesSkipped(result);
  out["skipped_by_server"] = result.skipped_by_server;
  out["poses_rejected"] = result.poses_rejected;
  out["latency_ms"] = {{"p50", Round3(Percentile(result.latency_ms, 0.50))},
                       {"p99", Round3(Percentile(result.latency_ms, 0.99))},
                       {"max", Round3(Max(result.latency_ms))}};
  out["server_solve_ms_p50"] = Round3(Percentile(result.solve_ms, 0.50));
  out["send_lag_max_ms"] = Round3(result.send_lag_max_ms);
  if (result.constrained_frames > 0) {
    out["constraints"] = {{"frames", result.constrained_frames},
                          {"penetrating_after_max", result.penetrating_after_max},
                          {"max_depth_after", result.max_depth_after},
                          {"frames_unresolved", result.frames_unresolved},
                          {"constraint_ms_p50", Round3(Percentile(result.constraint_ms, 0.50))}};
  }
  out["encoding"] = run.encoding;
  out["bytes_per_frame"] = Round3(BytesPerFrame(result));
  if (!run.out_path.empty()) out["out"] = run.out_path;
  return out;
}

std::string ReportText(const RunDescription& run, const PlaybackResult& result) {
  char buffer[1024];
  std::string text;
  std::snprintf(buffer, sizeof(buffer), "mesh %s (%s): %u vertices, %u triangles\n",
                run.mesh_id.c_str(), run.mesh_name.c_str(), run.vertices, run.triangles);
  text += buffer;
  if (run.pose.empty()) {
    std::snprintf(
        buffer, sizeof(buffer), "played %s: 0 -> %.1f -> 0 degrees every %.2f s, at %.1f Hz\n",
        (run.knee.joint + ":" + run.knee.axis).c_str(), run.peak_degrees, run.cycle_s, run.rate_hz);
  } else {
    std::snprintf(buffer, sizeof(buffer), "posed %s\n", run.pose.c_str());
  }
  text += buffer;
  std::snprintf(buffer, sizeof(buffer),
                "frames: %d sent, %d received, %d skipped (%llu reported by the server), %d "
                "rejected\n",
                result.poses_sent, result.frames_received, FramesSkipped(result),
                static_cast<unsigned long long>(result.skipped_by_server), result.poses_rejected);
  text += buffer;
  std::snprintf(buffer, sizeof(buffer),
                "pose-to-frame latency: p50 %.3f ms, p99 %.3f ms, max %.3f ms\n",
                Percentile(result.latency_ms, 0.50), Percentile(result.latency_ms, 0.99),
                Max(result.latency_ms));
  text += buffer;
  std::snprintf(buffer, sizeof(buffer), "server solve: median %.3f ms; worst send lag %.3f ms\n",
                Percentile(result.solve_ms, 0.50), result.send_lag_max_ms);
  text += buffer;
  if (result.constrained_frames > 0) {
    std::snprintf(buffer, sizeof(buffer),
                  "bones: skin inside a bone after the constraints at most %u vertices, deepest "
                  "%.3g; %d unresolved frames; constraints median %.3f ms\n",
                  result.penetrating_after_max, result.max_depth_after, result.frames_unresolved,
                  Percentile(result.constraint_ms, 0.50));
    text += buffer;
  }
  std::snprintf(buffer, sizeof(buffer), "frames %s: %.0f bytes per frame, %.3f bytes per vertex\n",
                run.encoding.c_str(), BytesPerFrame(result),
                BytesPerFrame(result) / std::max(run.vertices, 1u));
  text += buffer;
  if (!run.out_path.empty()) text += "wrote " + run.out_path + "\n";
  return text;
}

}  // namespace deform::vr
