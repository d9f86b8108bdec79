#include "loadtest/load_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "lib/status_names.h"

namespace deform::loadtest {
namespace {

// `value` rounded to `decimals` places (dividing by a power of ten keeps the JSON text short).
double Round(double value, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(value * scale) / scale;
}
double Ms(double value) { return Round(value, 3); }

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return PercentileOfSorted(values, 0.5);
}

ServerTimings MedianTimings(const std::vector<ServerTimings>& timings) {
  std::vector<double> queue, rhs, solve, encode, constraint;
  queue.reserve(timings.size());
  rhs.reserve(timings.size());
  solve.reserve(timings.size());
  encode.reserve(timings.size());
  constraint.reserve(timings.size());
  for (const ServerTimings& t : timings) {
    queue.push_back(t.queue_ms);
    rhs.push_back(t.rhs_ms);
    solve.push_back(t.solve_ms);
    encode.push_back(t.encode_ms);
    constraint.push_back(t.constraint_ms);
  }
  ServerTimings median;
  median.queue_ms = Median(std::move(queue));
  median.rhs_ms = Median(std::move(rhs));
  median.solve_ms = Median(std::move(solve));
  median.encode_ms = Median(std::move(encode));
  median.constraint_ms = Median(std::move(constraint));
  return median;
}

void Merge(const ConstraintStats& from, ConstraintStats* into) {
  into->frames += from.frames;
  into->frames_penetrating += from.frames_penetrating;
  into->frames_unresolved += from.frames_unresolved;
  into->penetrating_after_max = std::max(into->penetrating_after_max, from.penetrating_after_max);
  into->max_depth_after = std::max(into->max_depth_after, from.max_depth_after);
  into->contacts_sum += from.contacts_sum;
  into->contacts_max = std::max(into->contacts_max, from.contacts_max);
  into->volume_change_max_abs = std::max(into->volume_change_max_abs, from.volume_change_max_abs);
}

void CountError(LoadReport* report, const std::string& code, std::uint64_t count) {
  if (count == 0) return;
  report->errors += count;
  report->errors_by_code[code] += count;
}

}  // namespace

double LoadReport::delivered_fraction() const {
  return frames_sent == 0 ? 0.0
                          : static_cast<double>(frames_received) / static_cast<double>(frames_sent);
}

double LoadReport::throughput_fps() const {
  return plan.duration_s <= 0 ? 0.0 : static_cast<double>(frames_received) / plan.duration_s;
}

LoadReport BuildReport(const RunDescription& run, const LoadPlan& plan, RunOutcome* outcome) {
  LoadReport report;
  report.run = run;
  report.plan = plan;
  report.send_lag_max_ms = outcome->send_lag_max_ms;
  std::vector<ServerTimings> timings;
  std::vector<double> factor_ms;
  for (StreamOutcome& stream : outcome->streams) {
    StreamStats& stats = stream.stats;
    report.frames_sent += stream.poses_sent;
    report.frames_received += stats.frames_received;
    report.skipped_by_server += stats.skipped_by_server;
    report.poses_rejected += stats.poses_rejected;
    report.stiffness_rejected += stats.stiffness_rejected;
    report.bad_frames += stats.bad_frames;
    report.payload_bytes += stats.payload_bytes;
    report.stiffness_sent += stream.stiffness_sent;
    report.stiffness_applied += stats.stiffness_applied;
    report.max_gap_ms = std::max(report.max_gap_ms, stream.max_gap_ms);
    report.reconnects += stats.reconnects;
    report.latency_ms.insert(report.latency_ms.end(), stats.latency_ms.begin(),
                             stats.latency_ms.end());
    timings.insert(timings.end(), stats.timings.begin(), stats.timings.end());
    Merge(stats.constraints, &report.constraints);
    factor_ms.insert(factor_ms.end(), stats.stiffness_factor_ms.begin(),
                     stats.stiffness_factor_ms.end());
    stats.latency_ms = {};
    stats.timings = {};
    if (!stream.status.ok()) {
      CountError(&report, client::StatusCodeName(stream.status.error_code()), 1);
      if (report.first_stream_error.empty())
        report.first_stream_error = client::StatusText(stream.status);
    }
  }
  // latency_ms[i] and timings[i] are the same frame's (both appended per stream, in order).
  std::vector<double> server_total, outside_server;
  for (std::size_t i = 0; i < timings.size() && i < report.latency_ms.size(); ++i) {
    const ServerTimings& t = timings[i];
    const double total = t.queue_ms + t.rhs_ms + t.solve_ms + t.constraint_ms + t.encode_ms;
    server_total.push_back(total);
    outside_server.push_back(report.latency_ms[i] - total);
  }
  double batch_frames = 0, split = 0;
  for (const ServerTimings& t : timings) {
    batch_frames += std::max(t.batch_frames, 1);
    split += t.solve_parts > 1 ? 1 : 0;
  }
  if (!timings.empty()) {
    report.batch_frames_mean = batch_frames / static_cast<double>(timings.size());
    report.split_fraction = split / static_cast<double>(timings.size());
  }
  report.server_total = Summarize(&server_total);
  report.outside_server = Summarize(&outside_server);
  CountError(&report, "INVALID_ARGUMENT", report.poses_rejected + report.stiffness_rejected);
  CountError(&report, "DATA_LOSS", report.bad_frames);
  report.latency = Summarize(&report.latency_ms);
  report.server_p50 = MedianTimings(timings);
  report.stiffness_factor_ms_p50 = Median(std::move(factor_ms));
  return report;
}

nlohmann::ordered_json ReportJson(const LoadReport& report) {
  const LoadPlan& plan = report.plan;
  nlohmann::ordered_json out;
  out["target"] = report.run.target;
  out["mesh"] = report.run.mesh;
  out["mesh_id"] = report.run.mesh_id;
  out["acquire_ms"] = Round(report.run.acquire_ms, 3);
  out["vertices"] = report.run.vertices;
  out["triangles"] = report.run.triangles;
  out["rotation_blend"] = report.run.rotation_blend;
  out["encoding"] = report.run.encoding;
  out["streams"] = plan.streams;
  out["rate_hz"] = plan.rate_hz;
  out["duration_s"] = plan.duration_s;
  out["warmup_s"] = plan.warmup_s;
  out["posed"] = plan.posed.joint + ":" + plan.posed.axis;
  out["frames_sent"] = report.frames_sent;
  out["frames_received"] = report.frames_received;
  out["delivered_fraction"] = Round(report.delivered_fraction(), 5);
  out["skipped_by_server"] = report.skipped_by_server;
  out["errors"] = report.errors;
  out["errors_by_code"] = nlohmann::ordered_json::object();
  for (const auto& [code, count] : report.errors_by_code) out["errors_by_code"][code] = count;
  out["rejected_notices"] = {{"KIND_POSE_REJECTED", report.poses_rejected},
                             {"KIND_STIFFNESS_REJECTED", report.stiffness_rejected}};
  out["throughput_fps"] = Round(report.throughput_fps(), 1);
  const double frames = static_cast<double>(std::max<std::uint64_t>(report.frames_received, 1));
  out["bytes_per_frame"] = Round(static_cast<double>(report.payload_bytes) / frames, 1);
  out["bytes_per_vertex"] = Round(static_cast<double>(report.payload_bytes) / frames /
                                      static_cast<double>(std::max(report.run.vertices, 1u)),
                                  3);
  out["latency_ms"] = {{"p50", Ms(report.latency.p50)}, {"p90", Ms(report.latency.p90)},
                       {"p99", Ms(report.latency.p99)}, {"p999", Ms(report.latency.p999)},
                       {"max", Ms(report.latency.max)}, {"mean", Ms(report.latency.mean)}};
  out["max_gap_ms"] = Ms(report.max_gap_ms);
  out["reconnects"] = report.reconnects;
  out["stiffness_every_s"] = plan.stiffness_every_s;
  out["stiffness_joint"] = report.run.stiffness_joint;
  out["stiffness_updates_sent"] = report.stiffness_sent;
  out["stiffness_updates_applied"] = report.stiffness_applied;
  out["stiffness_factor_ms_p50"] = Ms(report.stiffness_factor_ms_p50);
  out["server_solve_ms_p50"] = Ms(report.server_p50.solve_ms);
  out["server_ms_p50"] = {{"queue", Ms(report.server_p50.queue_ms)},
                          {"rhs", Ms(report.server_p50.rhs_ms)},
                          {"solve", Ms(report.server_p50.solve_ms)},
                          {"constraints", Ms(report.server_p50.constraint_ms)},
                          {"encode", Ms(report.server_p50.encode_ms)}};
  const ConstraintStats& c = report.constraints;
  out["constraints"] = {{"frames", c.frames},
                        {"frames_penetrating", c.frames_penetrating},
                        {"frames_unresolved", c.frames_unresolved},
                        {"penetrating_after_max", c.penetrating_after_max},
                        {"max_depth_after", c.max_depth_after},
                        {"contacts_mean", Round(c.contacts_mean(), 2)},
                        {"contacts_max", c.contacts_max},
                        {"volume_change_max_abs", c.volume_change_max_abs}};
  out["server_total_ms"] = {{"p50", Ms(report.server_total.p50)},
                            {"p99", Ms(report.server_total.p99)},
                            {"max", Ms(report.server_total.max)}};
  out["outside_server_ms"] = {{"p50", Ms(report.outside_server.p50)},
                              {"p99", Ms(report.outside_server.p99)},
                              {"max", Ms(report.outside_server.max)}};
  out["server_batch_frames_mean"] = Round(report.batch_frames_mean, 3);
  out["server_split_fraction"] = Round(report.split_fraction, 4);
  out["send_lag_max_ms"] = Ms(report.send_lag_max_ms);
  return out;
}

std::string ReportText(const LoadReport& report) {
  const LoadPlan& plan = report.plan;
  const LatencySummary& l = report.latency;
  std::string text;
  char line[512];
  auto add = [&](const char* format, auto... values) {
    std::snprintf(line, sizeof(line), format, values...);
    text += line;
  };
  add("target %s, mesh %s (%s): %u vertices, %u triangles, %s rotation blend\n",
      report.run.target.c_str(), report.run.mesh.c_str(), report.run.mesh_id.c_str(),
      report.run.vertices, report.run.triangles, report.run.rotation_blend.c_str());
  const double frames = static_cast<double>(std::max<std::uint64_t>(report.frames_received, 1));
  add("frames %s: %.0f bytes per frame, %.3f bytes per vertex\n", report.run.encoding.c_str(),
      static_cast<double>(report.payload_bytes) / frames,
      static_cast<double>(report.payload_bytes) / frames / std::max(report.run.vertices, 1u));
  add("%d streams x %.1f Hz posing %s:%s, %.1f s measured after %.1f s warm-up\n", plan.streams,
      plan.rate_hz, plan.posed.joint.c_str(), plan.posed.axis.c_str(), plan.duration_s,
      plan.warmup_s);
  add("frames: %llu sent, %llu received (%.2f%%), %llu skipped by the server; %.1f frames/s\n",
      static_cast<unsigned long long>(report.frames_sent),
      static_cast<unsigned long long>(report.frames_received), 100.0 * report.delivered_fraction(),
      static_cast<unsigned long long>(report.skipped_by_server), report.throughput_fps());
  add("latency ms: p50 %.3f  p90 %.3f  p99 %.3f  p99.9 %.3f  max %.3f  (mean %.3f)\n", l.p50, l.p90,
      l.p99, l.p999, l.max, l.mean);
  add("largest gap between frames of one stream: %.3f ms\n", report.max_gap_ms);
  if (report.reconnects > 0) {
    add("streams opened again after losing their server: %llu\n",
        static_cast<unsigned long long>(report.reconnects));
  }
  add("server ms (median): queue %.3f  rhs %.3f  solve %.3f  constraints %.3f  encode %.3f\n",
      report.server_p50.queue_ms, report.server_p50.rhs_ms, report.server_p50.solve_ms,
      report.server_p50.constraint_ms, report.server_p50.encode_ms);
  if (report.constraints.frames > 0) {
    const ConstraintStats& c = report.constraints;
    add("constraints: %llu frames left skin inside a bone (at most %u vertices, %.3g deep), %llu "
        "unresolved; contacts mean %.1f max %u; |volume change| at most %.3g\n",
        static_cast<unsigned long long>(c.frames_penetrating), c.penetrating_after_max,
        c.max_depth_after, static_cast<unsigned long long>(c.frames_unresolved), c.contacts_mean(),
        c.contacts_max, c.volume_change_max_abs);
  }
  add("server total ms: p50 %.3f  p99 %.3f; outside the server (gRPC, wake-ups): p50 %.3f  p99 "
      "%.3f\n",
      report.server_total.p50, report.server_total.p99, report.outside_server.p50,
      report.outside_server.p99);
  add("server passes: %.2f frames per pass over the factor (mean), %.1f%% of frames split over "
      "threads\n",
      report.batch_frames_mean, 100.0 * report.split_fraction);
  if (plan.stiffness_every_s > 0) {
    add("stiffness on %s every %.2f s: %llu sent, %llu applied (median refactorization %.3f ms)\n",
        report.run.stiffness_joint.c_str(), plan.stiffness_every_s,
        static_cast<unsigned long long>(report.stiffness_sent),
        static_cast<unsigned long long>(report.stiffness_applied), report.stiffness_factor_ms_p50);
  }
  add("worst send lag against the schedule: %.3f ms\n", report.send_lag_max_ms);
  if (report.errors == 0) {
    text += "errors: none\n";
  } else {
    add("errors: %llu", static_cast<unsigned long long>(report.errors));
    for (const auto& [code, count] : report.errors_by_code) {
      add(" %s=%llu", code.c_str(), static_cast<unsigned long long>(count));
    }
    text += "\n";
    if (!report.first_stream_error.empty()) {
      text += "first stream error: " + report.first_stream_error + "\n";
    }
  }
  if (!report.latency_ms.empty()) {
    text += "latency histogram (ms, count, share, cumulative):\n";
    text += LatencyHistogramText(report.latency_ms);
  }
  return text;
}

}  // namespace deform::loadtest
