// The loaded meshes: ids, their deformation models, and the limits on what may be loaded.
//
// A MeshEntry is immutable once registered except for two atomics (unloaded, open_streams), which
// change only under the registry's lock (readers may read them without).
// Streams hold a shared_ptr to their entry, which keeps the model alive after UnloadMesh.
//
// Limits: the number of meshes loaded or being loaded (a Reservation is taken before the
// expensive work, so a client learns early that no slot is free) and a memory budget; both
// server-wide and per tenant (ServiceLimits::tenant_*). A load in progress holds memory in its
// reservation (ReserveMemory: an upload's declared bytes while they arrive, then the model's
// estimate before anything is built, DeformationModel::EstimateBytesBeforeBuild), so what does not
// fit is refused before it is allocated and two loads cannot both take the last of the budget; a
// registered mesh counts DeformationModel::EstimatedBytes() and its batch scratches instead, until
// it is unloaded and the last stream using it has ended (AttachStream / DetachStream): a model kept
// alive by streams after UnloadMesh still counts.
//
// Tenancy: every mesh belongs to the tenant that loaded it. The lookups that take a caller
// (Identity) answer another tenant's id exactly as an unknown id (NOT_FOUND, same message), so a
// caller cannot learn that it exists; an operator sees every mesh.
//
// Thread safety: all methods may be called from any thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/base/status.h"
#include "core/model/deformation_model.h"
#include "service/annotated_mutex.h"
#include "service/batch_scratch_pool.h"
#include "service/identity.h"
#include "service/service_options.h"
#include "service/thread_annotations.h"

namespace deform::service {

// What a mesh's file says beyond the solve's mesh: the order clients see its vertices in, units,
// up axis (from a glTF rig; empty for the other formats).
struct MeshPresentation {
  // Per vertex in the file's order (the order of frames, rest positions and vertex indices in the
  // API), its vertex of the solved mesh (every entry one of them: RigImport); empty when they are
  // the same.
  std::vector<int> file_vertex_to_mesh;
  // Of those, the ones no triangle uses (ascending): GetMeshInfo's triangles never name them, and
  // the summary warns of them.
  std::vector<int> unused_file_vertices;
  std::string units;
  std::string up_axis;
};

struct MeshEntry {
  std::string id;      // NewMeshId(): "mesh-" and 128 random bits in hex (mesh_id.h)
  std::string name;    // the client's label
  std::string tenant;  // the owner: the tenant that loaded it
  std::shared_ptr<const DeformationModel> model;
  double precompute_ms = 0;
  double factor_ms = 0;
  std::size_t factor_bytes = 0;
  std::size_t memory_bytes = 0;  // model->EstimatedBytes(), batch_scratches, the file-order maps
  MeshPresentation presentation;
  // The buffers of batched solves of the mesh's frames (in memory_bytes), with room for the
  // parallel plan's batches when there is one; null when its frames are solved one by one
  // (batching off, or a linear response: nothing to share).
  std::unique_ptr<BatchScratchPool> batch_scratches;
  // The split of the mesh's solve over the workers (one part each) for a lone frame or a batch
  // (FrameSolver::EnableParallel); null when the mesh is too small for it to pay
  // (SolveSettings::parallel_min_factor_bytes) or there is one worker. Streams size their
  // parallel work for it.
  std::unique_ptr<const ParallelSolvePlan> parallel_plan;

  // Vertices of frames and rest positions as clients see them (the file's).
  int client_vertex_count() const {
    return presentation.file_vertex_to_mesh.empty()
               ? model->mesh().num_vertices()
               : static_cast<int>(presentation.file_vertex_to_mesh.size());
  }

  mutable std::atomic<bool> unloaded{false};
  mutable std::atomic<int> open_streams{0};
};

// How meshes are prepared for the workers: `slots` batch scratches of `max_frames` frames each
// (one per worker; none when max_frames < 2), a parallel solve plan of `slots` parts for a mesh
// whose factor holds at least parallel_min_factor_bytes (slots >= 2), and the loader's
// ModelOptions::float32_factor_min_bytes (negative: every factor in double).
struct SolveSettings {
  int slots = 0;
  int max_frames = 1;
  std::size_t parallel_min_factor_bytes = std::size_t{8} << 20;
  std::int64_t float32_factor_min_bytes = -1;
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
    const std::string& tenant() const { return tenant_; }
    // The memory it holds against the budgets (MeshRegistry::ReserveMemory).
    std::size_t memory_bytes() const { return memory_bytes_; }
    void Release();

   private:
    friend class MeshRegistry;
    Reservation(MeshRegistry* registry, std::string tenant)
        : registry_(registry), tenant_(std::move(tenant)) {}
    MeshRegistry* registry_ = nullptr;
    std::string tenant_;
    std::size_t memory_bytes_ = 0;
  };

  // Memory a Deform stream holds beyond its mesh's model (its solve buffers and frames, its own
  // factorisations after stiffness updates), counted in the server's and its tenant's budgets
  // until it is resized to 0 or destroyed. Movable; the registry must outlive it.
  class MemoryHold {
   public:
    MemoryHold() = default;
    MemoryHold(MemoryHold&& other) noexcept;
    MemoryHold& operator=(MemoryHold&& other) noexcept;
    ~MemoryHold();
    // Makes the hold count `bytes` in place of what it counted. RESOURCE_EXHAUSTED naming `what`,
    // the need, the budget and what is in use when the growth does not fit; the hold then keeps
    // what it had. Shrinking always succeeds.
    Status Resize(std::size_t bytes, const std::string& what);
    std::size_t bytes() const { return bytes_; }

   private:
    friend class MeshRegistry;
    MemoryHold(MeshRegistry* registry, std::string tenant)
        : registry_(registry), tenant_(std::move(tenant)) {}
    MeshRegistry* registry_ = nullptr;
    std::string tenant_;
    std::size_t bytes_ = 0;
  };

  explicit MeshRegistry(const ServiceLimits& limits, SolveSettings solve_settings = {});
  MeshRegistry(const MeshRegistry&) = delete;
  MeshRegistry& operator=(const MeshRegistry&) = delete;

  const ServiceLimits& limits() const { return limits_; }
  const SolveSettings& solve_settings() const { return solve_settings_; }

  // A slot for a mesh `tenant` loads. RESOURCE_EXHAUSTED (naming the limit) when max_meshes are
  // loaded or being loaded, or tenant_max_meshes of `tenant`'s. The registry must outlive it.
  StatusOr<Reservation> Reserve(const std::string& tenant = Identity::Implicit().tenant);
  // Makes `reservation` (valid) hold `bytes` of the memory budgets, the server's and its tenant's,
  // in place of what it held: what the load will need next, known before it is allocated.
  // RESOURCE_EXHAUSTED naming `what`, the estimate, the budget and what is in use (by loaded
  // meshes and by other loads in progress) when it does not fit; the reservation then keeps what
  // it held.
  Status ReserveMemory(Reservation* reservation, std::size_t bytes, const std::string& what);

  // Registers a built model using `reservation`'s slot, owned by the reservation's tenant, under
  // `id` if given (a mesh restored from a store keeps its id; an id already loaded is
  // INVALID_ARGUMENT), else under a new NewMeshId(). RESOURCE_EXHAUSTED (the slot is released) when
  // the model does not fit in the memory budget.
  StatusOr<std::shared_ptr<const MeshEntry>> Register(Reservation reservation, std::string name,
                                                      std::shared_ptr<const DeformationModel> model,
                                                      MeshPresentation presentation = {},
                                                      std::string id = {});

  // The mesh `caller` may access; NOT_FOUND for an unknown (or unloaded) id and, with the same
  // message, for another tenant's mesh.
  StatusOr<std::shared_ptr<const MeshEntry>> Find(const std::string& mesh_id,
                                                  const Identity& caller) const;
  // The meshes `caller` may access, in the order they were loaded.
  std::vector<std::shared_ptr<const MeshEntry>> List(const Identity& caller) const;
  // Removes the mesh and marks it unloaded; NOT_FOUND as Find. Its memory stays counted until its
  // last stream detaches.
  Status Unload(const std::string& mesh_id, const Identity& caller);
  // A stream starts using `entry` (from Find): counted in entry.open_streams. NOT_FOUND (as Find)
  // when it has been unloaded since. Call DetachStream once for every successful AttachStream.
  Status AttachStream(const MeshEntry& entry);
  // The stream has ended; the last one of an unloaded mesh releases its memory from the budget.
  void DetachStream(const MeshEntry& entry);
  // An empty hold of `tenant`'s (MemoryHold::Resize counts memory in it).
  MemoryHold HoldMemory(const std::string& tenant);
  // Unscoped (the server's own use: preloads, a load whose client went away, tests).
  StatusOr<std::shared_ptr<const MeshEntry>> Find(const std::string& mesh_id) const;
  std::vector<std::shared_ptr<const MeshEntry>> List() const;
  Status Unload(const std::string& mesh_id);

  // Of the budget: the memory of loaded meshes and of unloaded ones streams still use, memory
  // held by loads in progress, and memory held by streams (MemoryHold).
  std::size_t memory_bytes_used() const;
  std::size_t memory_bytes_reserved() const;
  std::size_t memory_bytes_streams() const;
  int mesh_count() const;
  int loads_in_progress() const;
  // Meshes registered since the registry was made (unloaded ones included).
  int registrations() const;
  // Streams attached to any mesh now (every mesh's open_streams together), read without a lock.
  const std::atomic<int>& open_streams() const { return open_streams_; }

 private:
  // Per-tenant counts: slots held by loads in progress, loaded meshes, their memory.
  struct TenantUsage {
    int reserved = 0;
    int loaded = 0;
    std::size_t memory_bytes = 0;           // of loaded meshes and unloaded ones still streamed
    std::size_t reserved_memory_bytes = 0;  // held by loads in progress
    std::size_t stream_memory_bytes = 0;    // held by streams
  };
  void ReleaseSlot(const std::string& tenant, std::size_t memory_bytes);
  void ReleaseMemoryLocked(const MeshEntry& entry) DEFORM_REQUIRES(mutex_);
  // OK when `bytes` fit in the budgets besides what is in use, not counting `held` (what the
  // caller's own reservation holds already).
  Status CheckMemoryLocked(std::size_t bytes, std::size_t held, const std::string& tenant,
                           const std::string& what) const DEFORM_REQUIRES(mutex_);

  const ServiceLimits limits_;
  const SolveSettings solve_settings_;
  mutable Mutex mutex_;
  // By load order (a sequence number), and the sequence number of each id.
  std::map<std::uint64_t, std::shared_ptr<MeshEntry>> meshes_ DEFORM_GUARDED_BY(mutex_);
  std::unordered_map<std::string, std::uint64_t> order_of_id_ DEFORM_GUARDED_BY(mutex_);
  int reserved_ DEFORM_GUARDED_BY(mutex_) = 0;  // slots held by loads in progress
  // memory_bytes of loaded meshes, and of unloaded meshes whose streams have not all ended
  std::size_t memory_used_ DEFORM_GUARDED_BY(mutex_) = 0;
  std::size_t memory_retained_ DEFORM_GUARDED_BY(mutex_) = 0;  // of the latter alone
  std::size_t memory_reserved_ DEFORM_GUARDED_BY(mutex_) = 0;  // held by reservations
  std::size_t memory_streams_ DEFORM_GUARDED_BY(mutex_) = 0;   // held by MemoryHolds
  std::uint64_t next_order_ DEFORM_GUARDED_BY(mutex_) = 1;     // also counts registrations
  std::map<std::string, TenantUsage> tenants_ DEFORM_GUARDED_BY(mutex_);
  std::atomic<int> open_streams_{0};  // changed under mutex_, read without it
};

}  // namespace deform::service
