// What deform-vr prints after a playback: a few readable lines, or one JSON object.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "lib/joint_choice.h"
#include "vr/pose_player.h"

namespace deform::vr {

struct RunDescription {
  std::string mesh_id;
  std::string mesh_name;
  unsigned vertices = 0;
  unsigned triangles = 0;
  std::string pose;        // the scripted pose, or empty for the flexion trajectory
  client::JointAxis knee;  // the trajectory's joint and axis
  double peak_degrees = 0;
  double cycle_s = 0;
  double rate_hz = 0;
  std::string encoding;  // the frames' (--encoding)
  std::string out_path;
};

// One JSON object: the run's description, frame counts, latency percentiles (ms), median solve.
nlohmann::ordered_json ReportJson(const RunDescription& run, const PlaybackResult& result);

// The same as a few lines of text.
std::string ReportText(const RunDescription& run, const PlaybackResult& result);

}  // namespace deform::vr
