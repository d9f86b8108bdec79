// The loaded meshes: ids, their deformation models, and the limits on what may be loaded.
//
// A MeshEntry is immutable once registered except for two atomics (unloaded, open_streams).
// Streams hold a shared_ptr to their entry, which keeps the model alive after UnloadMesh.
//
// Limits: the number of meshes loaded or being loaded (a Reservation is taken before the
// expensive work, so a client learns early that no slot is free) and a memory budget checked
// against DeformationModel::EstimatedBytes() when the mesh is registered. Memory is released from
// the budget at unload, even while open streams still use the model until they end.
//
// Thread safety: all methods may be called from any thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/model/deformation_model.h"
#include "service/annotated_mutex.h"
#include "service/service_options.h"
#include "service/thread_annotations.h"

namespace deform::service {

// What a mesh's file says beyond the solve's mesh: the order clients see its vertices in, units,
// up axis (from a glTF rig; empty for the other formats).
struct MeshPresentation {
  // Per vertex in the file's order (the order of frames, rest positions and vertex indices in the
  // API), its vertex of the solved mesh; empty when they are the same.
  std::vector<int> file_vertex_to_mesh;
  std::string units;
  std::string up_axis;
};

struct MeshEntry {
  std::string id;    // "mesh-<n>", never reused within a server's life
  std::string name;  // the client's label
  std::shared_ptr<const DeformationModel> model;
  double precompute_ms = 0;
  double factor_ms = 0;
  std::size_t factor_bytes = 0;
  std::size_t memory_bytes = 0;  // model->EstimatedBytes()
  MeshPresentation presentation;

  // Vertices of frames and rest positions as clients see them (the file's).
  int client_vertex_count() const {
    return presentation.file_vertex_to_mesh.empty()
               ? model->mesh().num_vertices()
               : static_cast<int>(presentation.file_vertex_to_mesh.size());
  }

  mutable std::atomic<bool> unloaded{false};
  mutable std::atomic<int> open_streams{0};
};

class MeshRegistry {
 public:
  // A mesh slot held while a mesh loads. Releases the slot when destroyed unless committed.
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& other) noexcept;
    Reservation& operator=(Reservation&& other) noexcept;
    ~Reservation();
    bool valid() const { return registry_ != nullptr; }
    void Release();

   private:
    friend class MeshRegistry;
    explicit Reservation(MeshRegistry* registry) : registry_(registry) {}
    MeshRegistry* registry_ = nullptr;
  };

  explicit MeshRegistry(const ServiceLimits& limits);
  MeshRegistry(const MeshRegistry&) = delete;
  MeshRegistry& operator=(const MeshRegistry&) = delete;

  const ServiceLimits& limits() const { return limits_; }

  // RESOURCE_EXHAUSTED when max_meshes are loaded or being loaded. The registry must outlive it.
  StatusOr<Reservation> Reserve();
  // RESOURCE_EXHAUSTED when `bytes` more would not fit in the memory budget now (an early check
  // before the expensive precomputation; Register checks again).
  Status CheckMemoryAvailable(std::size_t bytes) const;

  // Registers a built model under a new id, using `reservation`'s slot. RESOURCE_EXHAUSTED (the
  // slot is released) when the model does not fit in the memory budget.
  StatusOr<std::shared_ptr<const MeshEntry>> Register(Reservation reservation, std::string name,
                                                      std::shared_ptr<const DeformationModel> model,
                                                      MeshPresentation presentation = {});

  // NOT_FOUND for an unknown (or unloaded) id.
  StatusOr<std::shared_ptr<const MeshEntry>> Find(const std::string& mesh_id) const;
  // Loaded meshes in the order they were loaded.
  std::vector<std::shared_ptr<const MeshEntry>> List() const;
  // Removes the mesh and marks it unloaded; NOT_FOUND for an unknown id.
  Status Unload(const std::string& mesh_id);

  std::size_t memory_bytes_used() const;
  int mesh_count() const;

 private:
  void ReleaseSlot();

  const ServiceLimits limits_;
  mutable Mutex mutex_;
  // By sequence number.
  std::map<std::uint64_t, std::shared_ptr<MeshEntry>> meshes_ DEFORM_GUARDED_BY(mutex_);
  int reserved_ DEFORM_GUARDED_BY(mutex_) = 0;             // slots held by loads in progress
  std::size_t memory_used_ DEFORM_GUARDED_BY(mutex_) = 0;  // sum of memory_bytes of loaded meshes
  std::uint64_t next_number_ DEFORM_GUARDED_BY(mutex_) = 1;
};

}  // namespace deform::service
