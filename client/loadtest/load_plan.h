// The load test's schedule: what every stream sends, and when.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "lib/joint_choice.h"

namespace deform::loadtest {

struct LoadPlan {
  std::string mesh_id;
  std::size_t vertex_count = 0;  // frames must carry 12 bytes per vertex (decoded)
  // How frames travel; the client library decodes them into positions.
  deform::v1::FrameEncoding encoding = deform::v1::FRAME_ENCODING_FLOAT32;
  int streams = 1;
  // Stream i sends pose k at t0 + (k + i / streams) / rate_hz: the streams are evenly staggered
  // within one period, each on an absolute (drift-free) schedule.
  double rate_hz = 90.0;
  // Poses of the first ceil(warmup_s * rate_hz) ticks are sent but not measured; those of the next
  // ceil(duration_s * rate_hz) ticks are.
  double warmup_s = 1.0;
  double duration_s = 10.0;
  client::JointAxis posed;      // the joint bent by every pose
  double peak_degrees = 120.0;  // flexion runs 0 -> peak -> 0 along a cosine ...
  double cycle_s = 2.0;         // ... once per cycle; stream i's phase is i / streams of a cycle
  // Every `stiffness_every_s` seconds of the measured period (0 = never), stream i sends the next
  // of `stiffness_updates` in turn, first at warmup + (i / streams) * stiffness_every_s.
  double stiffness_every_s = 0.0;
  std::vector<deform::v1::StiffnessUpdate> stiffness_updates;
  // After the last send: how long to wait for every stream's last frame, then for the streams to
  // finish after the half-close (streams still open are cancelled).
  double drain_s = 2.0;
  // Streams open themselves again when their server is lost (ReconnectPolicy, defaults).
  bool reconnect = false;
};

// A StiffnessUpdate giving `joint` the material {rigid 2, soft `soft`, seam 4} (the defaults, but
// for the soft weight).
deform::v1::StiffnessUpdate SoftWeightUpdate(const std::string& joint, double soft);

}  // namespace deform::loadtest
