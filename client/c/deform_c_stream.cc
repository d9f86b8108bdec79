// The C API's stream functions (deform_c.h): a DeformStream whose callbacks keep the newest frame
// and the recent notices in a StreamInbox that the caller polls.
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "c_api_errors.h"
#include "c_api_handles.h"
#include "deform_c.h"

namespace deform::c_api {
namespace {

constexpr std::size_t kMaxNotices = 64;

// The C# declarations of client/csharp/Deform.cs (P/Invoke, LayoutKind.Sequential) rely on these
// layouts (the ctest csharp_binding compares every struct's layout with the C compiler's).
static_assert(sizeof(deform_frame_info) == 80, "deform_frame_info's layout changed");
static_assert(sizeof(deform_joint_angle) == 24, "deform_joint_angle's layout changed");
static_assert(sizeof(deform_root_transform) == 56, "deform_root_transform's layout changed");

struct Notice {
  deform_notice_info info;
  std::string message;
};

// What the stream's callbacks (gRPC's threads) hand to the polling caller. Latest wins: a frame
// not yet taken is replaced by a newer one.
struct StreamInbox {
  std::mutex mutex;
  std::condition_variable changed;
  // Guarded by mutex.
  bool has_frame = false;            // a frame not yet handed out
  std::string positions;             // its float32 positions
  v1::DeformFrame frame;             // its fields, positions cleared
  std::int64_t arrival_ns = 0;       // when it arrived (client::MonotonicNanos)
  std::uint64_t frames_dropped = 0;  // replaced before being handed out, since the last one
  std::uint64_t stream_id = 0;       // the server's id of the stream (DeformFrame.stream_id)
  // The last frame handed out: its bone surface transforms and constraint report.
  bool handed_out = false;
  std::string handed_out_bones;
  v1::FrameConstraints handed_out_constraints;
  double handed_out_constraint_ms = 0;
  bool handed_out_constrained = false;
  std::deque<Notice> notices;  // oldest first, at most kMaxNotices
  bool ended = false;
  grpc::Status final_status;

  void OnFrame(const v1::DeformFrame& incoming) {
    const std::int64_t now = client::MonotonicNanos();
    std::lock_guard<std::mutex> lock(mutex);
    if (has_frame) ++frames_dropped;
    positions.assign(incoming.positions());
    frame.CopyFrom(incoming);
    stream_id = incoming.stream_id();
    frame.clear_positions();
    frame.clear_encoded();
    arrival_ns = now;
    has_frame = true;
    changed.notify_all();
  }

  void OnNotice(const v1::Notice& incoming) {
    Notice notice;
    notice.info.kind = static_cast<int>(incoming.kind());
    notice.info.sequence = incoming.sequence();
    notice.info.stiffness_version = incoming.stiffness_version();
    notice.info.factor_ms = incoming.factor_ms();
    notice.message = incoming.message();
    std::lock_guard<std::mutex> lock(mutex);
    if (notices.size() == kMaxNotices) notices.pop_front();
    notices.push_back(std::move(notice));
  }

  void OnDone(const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(mutex);
    ended = true;
    final_status = status;
    changed.notify_all();
  }
};

// STREAM_ENDED or the stream's error, for calls on a stream that is over.
deform_status EndedStatus(const grpc::Status& status, const char* function) {
  if (!status.ok()) return FromGrpc(status, function);
  return Fail(DEFORM_STREAM_ENDED, std::string(function) + ": the stream has ended");
}

}  // namespace
}  // namespace deform::c_api

// Declared after the inbox so that the stream (whose destructor cancels the call and waits for
// its last callback) is destroyed first.
struct deform_stream {
  std::shared_ptr<deform::client::DeformClient> client;
  std::uint32_t vertex_count = 0;
  std::shared_ptr<deform::c_api::StreamInbox> inbox;
  std::mutex send_mutex;
  std::uint64_t next_sequence = 1;  // guarded by send_mutex
  bool closed = false;              // guarded by send_mutex
  std::unique_ptr<deform::client::DeformStream> stream;
};

namespace deform::c_api {
namespace {

// Runs `send` (true when the message was queued) under the stream's send lock: STREAM_ENDED when
// the stream was closed, the stream's end (EndedStatus) when `send` fails.
template <typename Send>
deform_status SendLocked(deform_stream* stream, const char* function, Send&& send) {
  std::lock_guard<std::mutex> lock(stream->send_mutex);
  if (stream->closed) {
    return Fail(DEFORM_STREAM_ENDED, std::string(function) + ": the stream was closed");
  }
  if (!send()) {
    std::lock_guard<std::mutex> inbox_lock(stream->inbox->mutex);
    return EndedStatus(stream->inbox->final_status, function);
  }
  return Succeed();
}

// Sends `pose` with the next sequence number.
deform_status SendPose(deform_stream* stream, v1::PoseUpdate* pose, std::uint64_t* sequence,
                       const char* function) {
  return SendLocked(stream, function, [&] {
    pose->set_sequence(stream->next_sequence);
    pose->set_client_timestamp_ns(client::MonotonicNanos());
    if (!stream->stream->SendPose(*pose)) return false;
    if (sequence != nullptr) *sequence = stream->next_sequence;
    ++stream->next_sequence;
    return true;
  });
}

}  // namespace
}  // namespace deform::c_api

using deform::c_api::Fail;
using deform::c_api::FromGrpc;
using deform::c_api::Get;
using deform::c_api::Guarded;
using deform::c_api::Succeed;

extern "C" {

deform_status deform_stream_open(deform_client* client, const char* mesh_id,
                                 deform_encoding encoding, double max_error, deform_stream** out) {
  return Guarded(__func__, {{client, "client"}, {mesh_id, "mesh_id"}, {out, "out"}}, [&] {
    // A C caller may pass any int; in C++ loading an enum outside its values is undefined, so
    // the value is checked as the int it was passed as (its bytes), before it is used as an enum.
    static_assert(sizeof(deform_encoding) == sizeof(int), "a C enum is passed as an int");
    int raw_encoding = 0;
    std::memcpy(&raw_encoding, &encoding, sizeof raw_encoding);
    if (raw_encoding < DEFORM_ENCODING_FLOAT32 || raw_encoding > DEFORM_ENCODING_PREDICTED) {
      return Fail(DEFORM_INVALID_ARGUMENT, "deform_stream_open: unknown encoding " +
                                               std::to_string(raw_encoding) +
                                               " (1 float32, 2 quantized, 3 predicted)");
    }
    // The mesh's existence and vertex count now, rather than as the stream's end later.
    deform::v1::GetMeshInfoResponse info;
    const grpc::Status found = client->client->GetMeshInfo(mesh_id, false, &info);
    if (!found.ok()) return FromGrpc(found, "deform_stream_open");

    auto handle = std::make_unique<deform_stream>();
    handle->client = client->client;
    handle->vertex_count = info.summary().vertex_count();
    handle->inbox = std::make_shared<deform::c_api::StreamInbox>();
    deform::client::DeformClient::StreamCallbacks callbacks;
    std::shared_ptr<deform::c_api::StreamInbox> inbox = handle->inbox;
    callbacks.on_frame = [inbox](const deform::v1::DeformFrame& frame) { inbox->OnFrame(frame); };
    callbacks.on_notice = [inbox](const deform::v1::Notice& notice) { inbox->OnNotice(notice); };
    callbacks.on_done = [inbox](const grpc::Status& done) { inbox->OnDone(done); };
    deform::client::DeformClient::StreamOptions options;
    options.encoding = static_cast<deform::v1::FrameEncoding>(encoding);
    options.max_error = max_error;
    handle->stream = client->client->OpenStream(mesh_id, std::move(callbacks), options);
    *out = handle.release();
    return Succeed();
  });
}

deform_status deform_stream_vertex_count(const deform_stream* stream, uint32_t* count) {
  return Get(__func__, stream, "stream", count, "count",
             [](const deform_stream& s) { return s.vertex_count; });
}

deform_status deform_stream_id(deform_stream* stream, uint64_t* id) {
  return Guarded(__func__, {{stream, "stream"}, {id, "id"}}, [&] {
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::lock_guard<std::mutex> lock(inbox.mutex);
    if (inbox.stream_id == 0) {
      return Fail(DEFORM_NO_DATA, "deform_stream_id: no frame has arrived yet");
    }
    *id = inbox.stream_id;
    return Succeed();
  });
}

deform_status deform_stream_send_pose(deform_stream* stream, const deform_joint_angle* angles,
                                      size_t angle_count, const deform_joint_rotation* rotations,
                                      size_t rotation_count, const deform_root_transform* root,
                                      uint64_t* sequence) {
  return deform_stream_send_pose_with_tools(stream, angles, angle_count, rotations, rotation_count,
                                            root, nullptr, 0, sequence);
}

deform_status deform_stream_send_pose_with_tools(
    deform_stream* stream, const deform_joint_angle* angles, size_t angle_count,
    const deform_joint_rotation* rotations, size_t rotation_count,
    const deform_root_transform* root, const deform_tool* tools, size_t tool_count,
    uint64_t* sequence) {
  const char* const fn = tool_count > 0 ? __func__ : "deform_stream_send_pose";
  return Guarded(fn, {{stream, "stream"}}, [&] {
    if ((angles == nullptr && angle_count > 0) || (rotations == nullptr && rotation_count > 0) ||
        (tools == nullptr && tool_count > 0)) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  std::string(fn) + ": an array is NULL but its count is not 0");
    }
    deform::v1::PoseUpdate pose;
    for (size_t k = 0; k < angle_count; ++k) {
      if (angles[k].joint == nullptr || angles[k].axis == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT, std::string(fn) + ": angles[" + std::to_string(k) +
                                                 "] has a NULL joint or axis");
      }
      deform::v1::JointAngle* angle = pose.add_angles();
      angle->set_joint(angles[k].joint);
      angle->set_axis(angles[k].axis);
      angle->set_degrees(angles[k].degrees);
    }
    for (size_t k = 0; k < rotation_count; ++k) {
      if (rotations[k].joint == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT,
                    std::string(fn) + ": rotations[" + std::to_string(k) + "] has a NULL joint");
      }
      deform::v1::JointRotation* rotation = pose.add_rotations();
      rotation->set_joint(rotations[k].joint);
      rotation->set_w(rotations[k].w);
      rotation->set_x(rotations[k].x);
      rotation->set_y(rotations[k].y);
      rotation->set_z(rotations[k].z);
    }
    if (root != nullptr) {
      deform::v1::RootTransform* placement = pose.mutable_root();
      placement->mutable_translation()->set_x(root->tx);
      placement->mutable_translation()->set_y(root->ty);
      placement->mutable_translation()->set_z(root->tz);
      placement->mutable_rotation()->set_w(root->qw);
      placement->mutable_rotation()->set_x(root->qx);
      placement->mutable_rotation()->set_y(root->qy);
      placement->mutable_rotation()->set_z(root->qz);
    }
    for (size_t k = 0; k < tool_count; ++k) {
      const deform_tool& tool = tools[k];
      if (tool.shape == DEFORM_TOOL_SPHERE) {
        deform::client::AddSphereTool(tool.center[0], tool.center[1], tool.center[2], tool.radius,
                                      &pose);
      } else if (tool.shape == DEFORM_TOOL_CAPSULE) {
        deform::client::AddCapsuleTool(tool.center, tool.end, tool.radius, &pose);
      } else {
        return Fail(DEFORM_INVALID_ARGUMENT, std::string(fn) + ": tools[" + std::to_string(k) +
                                                 "] has shape " + std::to_string(tool.shape) +
                                                 ", neither DEFORM_TOOL_SPHERE nor _CAPSULE");
      }
    }
    return deform::c_api::SendPose(stream, &pose, sequence, fn);
  });
}

deform_status deform_stream_send_pose_text(deform_stream* stream, const char* pose_text,
                                           uint64_t* sequence) {
  return Guarded(__func__, {{stream, "stream"}, {pose_text, "pose"}}, [&] {
    deform::v1::PoseUpdate pose;
    std::string error;
    if (!deform::client::ParsePoseAngles(pose_text, &pose, &error)) {
      return Fail(DEFORM_INVALID_ARGUMENT, "deform_stream_send_pose_text: " + error);
    }
    return deform::c_api::SendPose(stream, &pose, sequence, "deform_stream_send_pose_text");
  });
}

deform_status deform_stream_send_stiffness(deform_stream* stream,
                                           const deform_joint_material* materials,
                                           size_t material_count,
                                           const deform_region_weight* regions, size_t region_count,
                                           const uint32_t* vertex_indices,
                                           const double* vertex_weights, size_t vertex_count) {
  return Guarded(__func__, {{stream, "stream"}}, [&] {
    if ((materials == nullptr && material_count > 0) || (regions == nullptr && region_count > 0) ||
        ((vertex_indices == nullptr || vertex_weights == nullptr) && vertex_count > 0)) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_stream_send_stiffness: an array is NULL but its count is not 0");
    }
    deform::v1::StiffnessUpdate update;
    for (size_t k = 0; k < material_count; ++k) {
      if (materials[k].joint == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT, "deform_stream_send_stiffness: materials[" +
                                                 std::to_string(k) + "] has a NULL joint");
      }
      deform::v1::JointMaterialUpdate* material = update.add_joint_materials();
      material->set_joint(materials[k].joint);
      material->mutable_material()->set_rigid(materials[k].rigid);
      material->mutable_material()->set_soft(materials[k].soft);
      material->mutable_material()->set_seam(materials[k].seam);
    }
    for (size_t k = 0; k < region_count; ++k) {
      if (regions[k].joint == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT, "deform_stream_send_stiffness: regions[" +
                                                 std::to_string(k) + "] has a NULL joint");
      }
      deform::v1::RegionWeight* region = update.add_region_weights();
      region->set_joint(regions[k].joint);
      region->set_weight(regions[k].weight);
    }
    for (size_t k = 0; k < vertex_count; ++k) {
      update.add_vertex_indices(vertex_indices[k]);
      update.add_vertex_weights(vertex_weights[k]);
    }
    return deform::c_api::SendLocked(stream, "deform_stream_send_stiffness",
                                     [&] { return stream->stream->SendStiffness(update); });
  });
}

deform_status deform_stream_next_frame(deform_stream* stream, float* positions,
                                       size_t capacity_floats, int timeout_ms,
                                       deform_frame_info* info) {
  return Guarded(__func__, {{stream, "stream"}, {positions, "positions"}}, [&] {
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::unique_lock<std::mutex> lock(inbox.mutex);
    const auto ready = [&inbox] { return inbox.has_frame || inbox.ended; };
    if (timeout_ms < 0) {
      inbox.changed.wait(lock, ready);
    } else if (timeout_ms > 0) {
      inbox.changed.wait_for(lock, std::chrono::milliseconds(timeout_ms), ready);
    }
    if (inbox.has_frame) {
      const std::size_t floats = inbox.positions.size() / sizeof(float);
      if (capacity_floats < floats) {
        return Fail(DEFORM_INVALID_ARGUMENT,
                    "deform_stream_next_frame: the buffer holds " +
                        std::to_string(capacity_floats) + " floats; the frame needs " +
                        std::to_string(floats) + " (3 x " + std::to_string(floats / 3) +
                        " vertices); the frame is kept for a larger buffer");
      }
      std::memcpy(positions, inbox.positions.data(), floats * sizeof(float));
      if (info != nullptr) {
        const deform::v1::DeformFrame& frame = inbox.frame;
        const std::int64_t now = deform::client::MonotonicNanos();
        info->sequence = frame.sequence();
        info->client_timestamp_ns = frame.client_timestamp_ns();
        info->latency_ms = frame.client_timestamp_ns() != 0
                               ? (inbox.arrival_ns - frame.client_timestamp_ns()) / 1e6
                               : 0.0;
        info->age_ms = (now - inbox.arrival_ns) / 1e6;
        info->frames_dropped = inbox.frames_dropped;
        info->skipped_poses = frame.skipped_poses();
        info->clamped_angles = frame.clamped_angles();
        info->stiffness_version = frame.stiffness_version();
        const deform::v1::FrameTimings& t = frame.timings();
        info->server_ms =
            t.queue_ms() + t.rhs_ms() + t.solve_ms() + t.constraint_ms() + t.encode_ms();
        info->vertex_count = static_cast<uint32_t>(floats / 3);
        info->mesh_unloaded = frame.mesh_unloaded() ? 1 : 0;
      }
      inbox.handed_out = true;
      inbox.handed_out_bones.assign(inbox.frame.bone_transforms());
      inbox.handed_out_constrained = inbox.frame.has_constraints();
      inbox.handed_out_constraints.CopyFrom(inbox.frame.constraints());
      inbox.handed_out_constraint_ms = inbox.frame.timings().constraint_ms();
      inbox.has_frame = false;
      inbox.frames_dropped = 0;
      return Succeed();
    }
    if (inbox.ended) {
      return deform::c_api::EndedStatus(inbox.final_status, "deform_stream_next_frame");
    }
    return Fail(DEFORM_NO_DATA,
                "deform_stream_next_frame: no frame within " + std::to_string(timeout_ms) + " ms");
  });
}

deform_status deform_stream_frame_bones(deform_stream* stream, float* transforms,
                                        size_t capacity_floats,
                                        deform_frame_constraints* constraints) {
  return Guarded(__func__, {{stream, "stream"}, {constraints, "constraints"}}, [&] {
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::lock_guard<std::mutex> lock(inbox.mutex);
    if (!inbox.handed_out) {
      return Fail(DEFORM_NO_DATA, "deform_stream_frame_bones: no frame was handed out yet");
    }
    const std::vector<deform::client::BoneSurfaceMotion> motions =
        deform::client::DecodeBoneTransforms(inbox.handed_out_bones);
    *constraints = {};
    constraints->bone_surface_count = static_cast<uint32_t>(motions.size());
    if (capacity_floats < 12 * motions.size()) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_stream_frame_bones: the buffer holds " + std::to_string(capacity_floats) +
                      " floats; the frame's bones need " + std::to_string(12 * motions.size()));
    }
    if (!motions.empty() && transforms == nullptr) {
      return Fail(DEFORM_INVALID_ARGUMENT, "deform_stream_frame_bones: transforms is NULL");
    }
    for (std::size_t s = 0; s < motions.size(); ++s) {
      std::memcpy(transforms + 12 * s, motions[s].rotation, sizeof(motions[s].rotation));
      std::memcpy(transforms + 12 * s + 9, motions[s].translation, sizeof(motions[s].translation));
    }
    const deform::v1::FrameConstraints& c = inbox.handed_out_constraints;
    constraints->constrained = inbox.handed_out_constrained ? 1 : 0;
    constraints->penetrating_before = c.penetrating_before();
    constraints->penetrating_after = c.penetrating_after();
    constraints->max_depth_after = c.max_depth_after();
    constraints->unresolved = c.unresolved() ? 1 : 0;
    constraints->contacts = c.contacts();
    constraints->volume_change = c.volume_change();
    constraints->constraint_ms = inbox.handed_out_constraint_ms;
    return Succeed();
  });
}

deform_status deform_stream_frame_tools(deform_stream* stream, deform_frame_tools* tools) {
  return Guarded(__func__, {{stream, "stream"}, {tools, "tools"}}, [&] {
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::lock_guard<std::mutex> lock(inbox.mutex);
    if (!inbox.handed_out) {
      return Fail(DEFORM_NO_DATA, "deform_stream_frame_tools: no frame was handed out yet");
    }
    const deform::v1::FrameConstraints& c = inbox.handed_out_constraints;
    *tools = {};
    tools->penetrating_before = c.tool_penetrating_before();
    tools->penetrating_after = c.tool_penetrating_after();
    tools->max_depth_after = c.tool_max_depth_after();
    tools->contacts = c.tool_contacts();
    tools->unresolved = c.tools_unresolved() ? 1 : 0;
    return Succeed();
  });
}

deform_status deform_stream_next_notice(deform_stream* stream, deform_notice_info* info,
                                        char* message, size_t message_capacity) {
  return Guarded(__func__, {{stream, "stream"}, {info, "info"}}, [&] {
    if (message == nullptr && message_capacity > 0) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_stream_next_notice: message is NULL, message_capacity > 0");
    }
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::lock_guard<std::mutex> lock(inbox.mutex);
    if (inbox.notices.empty()) {
      return Fail(DEFORM_NO_DATA, "deform_stream_next_notice: no notice waiting");
    }
    const deform::c_api::Notice& notice = inbox.notices.front();
    *info = notice.info;
    if (message_capacity > 0) {
      const std::size_t length = std::min(notice.message.size(), message_capacity - 1);
      std::memcpy(message, notice.message.data(), length);
      message[length] = '\0';
    }
    inbox.notices.pop_front();
    return Succeed();
  });
}

deform_status deform_stream_close(deform_stream* stream, int timeout_ms) {
  return Guarded(__func__, {{stream, "stream"}}, [&] {
    {
      std::lock_guard<std::mutex> lock(stream->send_mutex);
      stream->closed = true;
      stream->stream->Close();
    }
    deform::c_api::StreamInbox& inbox = *stream->inbox;
    std::unique_lock<std::mutex> lock(inbox.mutex);
    const auto ended = [&inbox] { return inbox.ended; };
    if (timeout_ms < 0) {
      inbox.changed.wait(lock, ended);
    } else if (!inbox.changed.wait_for(lock, std::chrono::milliseconds(timeout_ms), ended)) {
      lock.unlock();
      stream->stream->Cancel();
      return Fail(DEFORM_DEADLINE_EXCEEDED, "deform_stream_close: the stream had not ended after " +
                                                std::to_string(timeout_ms) +
                                                " ms; it was cancelled");
    }
    return FromGrpc(inbox.final_status, "deform_stream_close");
  });
}

void deform_stream_free(deform_stream* stream) { delete stream; }

}  // extern "C"
