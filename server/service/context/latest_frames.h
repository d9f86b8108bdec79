// The latest solved skin of every open Deform stream, for the contact queries that name one
// (QueryContact, ContactQueryStart.deform_stream_id).
//
// A LatestFrame is one stream's: its buffer is allocated once, when the stream starts, and the
// stream's solve task copies each solved frame into it (Publish) under the frame's own mutex,
// held only for that copy (never across a solve); readers copy it out the same way (CopyIfNewer)
// and test for a newer frame without the lock (frame_number). No allocation per frame.
//
// LatestFrames maps stream ids to them, scoped by tenant as meshes are: another tenant's stream
// is NOT_FOUND with the same message as an unknown id. A query keeps its LatestFrame alive after
// the Deform stream ends (its last frame stays the skin it answers against).
//
// Thread safety: both classes are thread-safe; one publisher per LatestFrame.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "service/access/identity.h"
#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

class LatestFrame {
 public:
  // A frame of `vertices` vertices (the solved mesh's order) for a stream of `tenant` on mesh
  // `mesh_id`; holds 3 * vertices doubles (Bytes).
  LatestFrame(std::string tenant, std::string mesh_id, int vertices);
  static std::size_t Bytes(int vertices) { return sizeof(double) * 3 * vertices; }

  // The stream's solve task: the solved positions `xyz` (3 * vertices doubles, row i at
  // xyz[3 i]) of the frame that answered pose `sequence`. No allocation.
  void Publish(const double* xyz, std::uint64_t sequence) DEFORM_EXCLUDES(mutex_);
  // The number of frames published so far (0: none), without the lock.
  std::uint64_t frame_number() const { return frame_number_.load(std::memory_order_acquire); }
  // When a frame newer than `have` has been published: copies it into `xyz` (3 * vertices
  // doubles), sets its number and pose sequence, and returns true. No allocation.
  bool CopyIfNewer(std::uint64_t have, double* xyz, std::uint64_t* number,
                   std::uint64_t* sequence) const DEFORM_EXCLUDES(mutex_);

  const std::string& tenant() const { return tenant_; }
  const std::string& mesh_id() const { return mesh_id_; }
  int vertices() const { return vertices_; }

 private:
  const std::string tenant_;
  const std::string mesh_id_;
  const int vertices_;
  mutable Mutex mutex_;
  std::vector<double> xyz_ DEFORM_GUARDED_BY(mutex_);
  std::uint64_t sequence_ DEFORM_GUARDED_BY(mutex_) = 0;
  std::atomic<std::uint64_t> frame_number_{0};  // written under mutex_
};

class LatestFrames {
 public:
  void Add(std::uint64_t stream_id, std::shared_ptr<LatestFrame> frame) DEFORM_EXCLUDES(mutex_);
  void Remove(std::uint64_t stream_id) DEFORM_EXCLUDES(mutex_);
  // The frame of stream `stream_id` if `caller` may see it (Identity::CanAccess); NOT_FOUND
  // "no open Deform stream <id>" otherwise.
  StatusOr<std::shared_ptr<const LatestFrame>> Find(std::uint64_t stream_id,
                                                    const Identity& caller) const
      DEFORM_EXCLUDES(mutex_);
  int count() const DEFORM_EXCLUDES(mutex_);

 private:
  mutable Mutex mutex_;
  std::map<std::uint64_t, std::shared_ptr<LatestFrame>> frames_ DEFORM_GUARDED_BY(mutex_);
};

}  // namespace deform::service
