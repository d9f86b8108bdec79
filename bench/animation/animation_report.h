// What deform-animation-bench prints: a row per frame (the method's volume change and clearance
// beside LBS's for the same pose, the rigid-zone error, the round-trip latency) and a summary
// (median and worst of each, latency p50 / p99, the five worst frames by volume change and by
// rigid-zone error), as text or as one JSON object.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "animation/frame_measures.h"

namespace deform::animation {

struct FrameRecord {
  int frame = 0;      // 0-based index in the animation
  int line = 0;       // its line in the animation file (0 for a glTF animation)
  double time_s = 0;  // its time in a glTF animation
  FrameMeasures measures;
  double round_trip_ms = 0;
  double server_solve_ms = 0;  // the frame's timings.rhs_ms + solve_ms
  int clamped_angles = 0;
};

struct RunHeader {
  std::string mesh;            // what was loaded (path, or "phantom:N")
  std::string mesh_id;         // the server's id
  std::string rotation_blend;  // "quaternion" or "linear"
  std::string binding;         // "through the body" or "given weights"
  int frame_vertices = 0;      // vertices of a frame (the file's order)
  int solved_vertices = 0;     // vertices of the solved mesh (after glTF welding)
  int rigid_vertices = 0;      // vertices in a rigid zone (the rigid-zone error's domain)
  double local_build_ms = 0;   // building the local reference model
  std::string animation;       // the glTF animation played (empty for an animation file)
};

// Index of the worst element: the largest |value| (volume change), or the smallest / largest value.
enum class Worst { kLargestMagnitude, kSmallest, kLargest };

struct MetricSummary {
  double median = 0;
  double worst = 0;
  int worst_frame = 0;
};

MetricSummary Summarize(const std::vector<double>& values, Worst worst);

// The `count` frames worst by `values` (as `worst` orders them), worst first; ties by frame index.
std::vector<int> WorstFrames(const std::vector<double>& values, Worst worst, int count);

// Nearest-rank percentile (q in [0, 1]); 0 for none.
double Percentile(std::vector<double> values, double q);

std::string ReportText(const RunHeader& header, const std::vector<FrameRecord>& frames);
nlohmann::ordered_json ReportJson(const RunHeader& header, const std::vector<FrameRecord>& frames);

}  // namespace deform::animation
