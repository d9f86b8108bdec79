#include "animation/animation_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>

#include "core/base/median.h"

namespace deform::animation {
namespace {

constexpr int kWorstFramesListed = 5;

// True when a is worse than b.
bool Worse(double a, double b, Worst worst) {
  switch (worst) {
    case Worst::kLargestMagnitude:
      return std::abs(a) > std::abs(b);
    case Worst::kSmallest:
      return a < b;
    case Worst::kLargest:
      return a > b;
  }
  return false;
}

// A column of the per-frame table and of the summary.
struct Metric {
  const char* key;    // JSON name
  const char* title;  // text summary name
  Worst worst;
  std::function<double(const FrameRecord&)> value;
};

const std::vector<Metric>& Metrics() {
  static const std::vector<Metric> metrics = {
      {"volume_change", "volume change", Worst::kLargestMagnitude,
       [](const FrameRecord& r) { return r.measures.volume_change; }},
      {"lbs_volume_change", "LBS volume change", Worst::kLargestMagnitude,
       [](const FrameRecord& r) { return r.measures.lbs_volume_change; }},
      {"clearance_min", "clearance min", Worst::kSmallest,
       [](const FrameRecord& r) { return r.measures.clearance_min; }},
      {"lbs_clearance_min", "LBS clearance min", Worst::kSmallest,
       [](const FrameRecord& r) { return r.measures.lbs_clearance_min; }},
      {"clearance_p01", "clearance p01", Worst::kSmallest,
       [](const FrameRecord& r) { return r.measures.clearance_p01; }},
      {"lbs_clearance_p01", "LBS clearance p01", Worst::kSmallest,
       [](const FrameRecord& r) { return r.measures.lbs_clearance_p01; }},
      {"rigid_zone_error", "rigid-zone error", Worst::kLargest,
       [](const FrameRecord& r) { return r.measures.rigid_zone_error; }},
      {"latency_ms", "latency ms", Worst::kLargest,
       [](const FrameRecord& r) { return r.round_trip_ms; }},
      {"server_solve_ms", "server solve ms", Worst::kLargest,
       [](const FrameRecord& r) { return r.server_solve_ms; }},
  };
  return metrics;
}

std::vector<double> Column(const std::vector<FrameRecord>& frames, const Metric& metric) {
  std::vector<double> values;
  values.reserve(frames.size());
  for (const FrameRecord& record : frames) values.push_back(metric.value(record));
  return values;
}

const Metric& MetricNamed(const std::string& key) {
  for (const Metric& metric : Metrics()) {
    if (key == metric.key) return metric;
  }
  return Metrics().front();
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string Percent(double fraction) { return Format("%+.2f%%", 100.0 * fraction); }

}  // namespace

MetricSummary Summarize(const std::vector<double>& values, Worst worst) {
  MetricSummary summary;
  if (values.empty()) return summary;
  summary.median = Median(values);
  summary.worst_frame = WorstFrames(values, worst, 1).front();
  summary.worst = values[static_cast<std::size_t>(summary.worst_frame)];
  return summary;
}

std::vector<int> WorstFrames(const std::vector<double>& values, Worst worst, int count) {
  std::vector<int> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return Worse(values[a], values[b], worst); });
  order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(count)));
  return order;
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

std::string ReportText(const RunHeader& header, const std::vector<FrameRecord>& frames) {
  std::string out;
  out += "mesh " + header.mesh + " (" + header.mesh_id +
         "): " + std::to_string(header.frame_vertices) + " vertices per frame, " +
         std::to_string(header.solved_vertices) + " solved, " +
         std::to_string(header.rigid_vertices) + " in rigid zones\n";
  out += "rotation blend " + header.rotation_blend + "; binding " + header.binding +
         "; reference: the same DeformationModel::Build on the same inputs and options, built "
         "locally in " +
         Format("%.0f", header.local_build_ms) + " ms (so the same binding and weights)\n";
  if (!header.animation.empty()) out += "glTF animation " + header.animation + "\n";
  out += "LBS: linear blend skinning of the same pose with the model's weights\n\n";
  char line[256];
  std::snprintf(line, sizeof(line), "%6s %6s %10s %10s %10s %10s %12s %10s\n", "frame", "line",
                "volume", "LBS vol", "clear min", "LBS clear", "rigid err", "latency ms");
  out += line;
  for (const FrameRecord& r : frames) {
    std::snprintf(line, sizeof(line), "%6d %6d %10s %10s %10.3f %10.3f %12.2e %10.2f\n", r.frame,
                  r.line, Percent(r.measures.volume_change).c_str(),
                  Percent(r.measures.lbs_volume_change).c_str(), r.measures.clearance_min,
                  r.measures.lbs_clearance_min, r.measures.rigid_zone_error, r.round_trip_ms);
    out += line;
  }
  out += "\nsummary over " + std::to_string(frames.size()) +
         " frames (worst: largest |volume "
         "change|, smallest clearance, largest error and latency)\n";
  std::snprintf(line, sizeof(line), "  %-18s %12s %12s %8s\n", "", "median", "worst", "frame");
  out += line;
  for (const Metric& metric : Metrics()) {
    const MetricSummary s = Summarize(Column(frames, metric), metric.worst);
    const bool volume = metric.worst == Worst::kLargestMagnitude;
    const bool error = std::string(metric.key) == "rigid_zone_error";
    const char* format = error ? "%12.2e" : "%12.3f";
    std::snprintf(line, sizeof(line), "  %-18s %12s %12s %8d\n", metric.title,
                  volume ? Percent(s.median).c_str() : Format(format, s.median).c_str(),
                  volume ? Percent(s.worst).c_str() : Format(format, s.worst).c_str(),
                  s.worst_frame);
    out += line;
  }
  const std::vector<double> latency = Column(frames, MetricNamed("latency_ms"));
  std::snprintf(line, sizeof(line), "  latency p50 %.2f ms, p99 %.2f ms\n",
                Percentile(latency, 0.50), Percentile(latency, 0.99));
  out += line;
  for (const char* key : {"volume_change", "rigid_zone_error"}) {
    const Metric& metric = MetricNamed(key);
    const std::vector<double> values = Column(frames, metric);
    out += std::string("  worst frames by ") + metric.title + ":";
    for (int f : WorstFrames(values, metric.worst, kWorstFramesListed)) {
      const double v = values[static_cast<std::size_t>(f)];
      out += " " + std::to_string(f) + " (" +
             (metric.worst == Worst::kLargestMagnitude ? Percent(v) : Format("%.2e", v)) + ")";
    }
    out += "\n";
  }
  return out;
}

nlohmann::ordered_json ReportJson(const RunHeader& header, const std::vector<FrameRecord>& frames) {
  nlohmann::ordered_json out;
  out["mesh"] = header.mesh;
  out["mesh_id"] = header.mesh_id;
  out["rotation_blend"] = header.rotation_blend;
  out["binding"] = header.binding;
  out["reference"] =
      "the same DeformationModel::Build on the same inputs and options, built locally: the "
      "server's binding and weights; LBS with those weights";
  out["frame_vertices"] = header.frame_vertices;
  out["solved_vertices"] = header.solved_vertices;
  out["rigid_vertices"] = header.rigid_vertices;
  out["local_build_ms"] = header.local_build_ms;
  if (!header.animation.empty()) out["animation"] = header.animation;
  out["frames"] = frames.size();

  nlohmann::ordered_json per_frame;
  std::vector<int> index, line, clamped;
  for (const FrameRecord& r : frames) {
    index.push_back(r.frame);
    line.push_back(r.line);
    clamped.push_back(r.clamped_angles);
  }
  per_frame["frame"] = index;
  per_frame["line"] = line;
  if (!header.animation.empty()) {
    std::vector<double> time;
    for (const FrameRecord& r : frames) time.push_back(r.time_s);
    per_frame["time_s"] = time;
  }
  for (const Metric& metric : Metrics()) per_frame[metric.key] = Column(frames, metric);
  per_frame["clamped_angles"] = clamped;
  out["per_frame"] = per_frame;

  nlohmann::ordered_json summary;
  for (const Metric& metric : Metrics()) {
    const MetricSummary s = Summarize(Column(frames, metric), metric.worst);
    summary[metric.key] = {
        {"median", s.median}, {"worst", s.worst}, {"worst_frame", s.worst_frame}};
  }
  const std::vector<double> latency = Column(frames, MetricNamed("latency_ms"));
  summary["latency_ms"]["p50"] = Percentile(latency, 0.50);
  summary["latency_ms"]["p99"] = Percentile(latency, 0.99);
  out["summary"] = summary;

  nlohmann::ordered_json worst;
  for (const char* key : {"volume_change", "rigid_zone_error"}) {
    const Metric& metric = MetricNamed(key);
    const std::vector<double> values = Column(frames, metric);
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (int f : WorstFrames(values, metric.worst, kWorstFramesListed)) {
      list.push_back({{"frame", f}, {"value", values[static_cast<std::size_t>(f)]}});
    }
    worst[key] = list;
  }
  out["worst_frames"] = worst;
  return out;
}

}  // namespace deform::animation
