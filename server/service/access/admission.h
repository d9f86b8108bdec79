// Admission: what may be loaded and held at once, server-wide and per tenant. The one home of the
// service's resource limits (ServiceLimits): mesh slots, the memory budget and open streams.
//
//  - Mesh slots: meshes loaded or being loaded, against max_meshes and tenant_max_meshes. A load
//    takes a MeshSlot before its expensive work, so a client learns early that no slot is free.
//  - Memory: loaded meshes (their estimate, DeformationModel::EstimatedBytes and what the service
//    adds), unloaded meshes that streams still use, loads in progress (a MeshSlot holds what the
//    load will need next before it is allocated: an upload's declared bytes, then the model's
//    estimate) and streams' own buffers (MemoryHold), against max_memory_bytes and
//    tenant_max_memory_bytes. What does not fit is refused before it is allocated, and two loads
//    cannot both take the last of the budget.
//  - Streams: open Deform streams against max_streams and tenant_max_streams.
//
// Every refusal is RESOURCE_EXHAUSTED naming the limit (its deformd flag), the need and what is in
// use. A per-tenant limit of 0, or max_streams 0, means none.
//
// Thread safety: all methods may be called from any thread. Admission takes its own lock only and
// calls nothing outside itself while holding it, so callers may hold their own locks (the mesh
// registry does) while they call in.
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "core/base/status.h"
#include "service/access/identity.h"
#include "service/base/annotated_mutex.h"
#include "service/base/service_options.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

class Admission {
 public:
  // A mesh slot held while a mesh loads, and the memory the load holds (ReserveMemory). Releases
  // both when destroyed unless AdmitMesh took it. Movable; the Admission must outlive it.
  class MeshSlot {
   public:
    MeshSlot() = default;
    MeshSlot(MeshSlot&& other) noexcept;
    MeshSlot& operator=(MeshSlot&& other) noexcept;
    ~MeshSlot();
    bool valid() const { return admission_ != nullptr; }
    const std::string& tenant() const { return tenant_; }
    std::size_t memory_bytes() const { return memory_bytes_; }
    void Release();

   private:
    friend class Admission;
    MeshSlot(Admission* admission, std::string tenant)
        : admission_(admission), tenant_(std::move(tenant)) {}
    Admission* admission_ = nullptr;
    std::string tenant_;
    std::size_t memory_bytes_ = 0;
  };

  // Memory a Deform stream holds beyond its mesh's model (its solve buffers and frames, its own
  // factorizations after stiffness updates), counted in the server's and its tenant's budgets
  // until it is resized to 0 or destroyed. Movable; the Admission must outlive it.
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
    friend class Admission;
    MemoryHold(Admission* admission, std::string tenant)
        : admission_(admission), tenant_(std::move(tenant)) {}
    Admission* admission_ = nullptr;
    std::string tenant_;
    std::size_t bytes_ = 0;
  };

  explicit Admission(const ServiceLimits& limits) : limits_(limits) {}
  Admission(const Admission&) = delete;
  Admission& operator=(const Admission&) = delete;

  const ServiceLimits& limits() const { return limits_; }

  // A slot for a mesh `tenant` loads. RESOURCE_EXHAUSTED when max_meshes are loaded or being
  // loaded, or tenant_max_meshes of `tenant`'s.
  StatusOr<MeshSlot> ReserveMesh(const std::string& tenant = Identity::Implicit().tenant);
  // Makes `slot` (valid) hold `bytes` of the memory budgets in place of what it held: what the
  // load will need next, known before it is allocated. On refusal the slot keeps what it held.
  Status ReserveMemory(MeshSlot* slot, std::size_t bytes, const std::string& what);
  // The load of `slot` (valid) has built a mesh of `bytes`: the slot becomes a loaded mesh of its
  // tenant's, counted until MeshUnloaded. RESOURCE_EXHAUSTED when `bytes` do not fit; the slot
  // and its memory are released either way.
  Status AdmitMesh(MeshSlot slot, std::size_t bytes);
  // A mesh AdmitMesh counted is unloaded: it no longer takes a slot. Its `bytes` stay counted
  // while `still_in_use` (streams use it) until ReleaseUnloadedMesh, else they are released now.
  void MeshUnloaded(const std::string& tenant, std::size_t bytes, bool still_in_use);
  void ReleaseUnloadedMesh(const std::string& tenant, std::size_t bytes);
  // An empty hold of `tenant`'s (MemoryHold::Resize counts memory in it).
  MemoryHold HoldMemory(const std::string& tenant);
  // One more open stream of `tenant`; RESOURCE_EXHAUSTED when max_streams are open already, or
  // tenant_max_streams of `tenant`'s. ReleaseStream() once for every successful AcquireStream().
  Status AcquireStream(const std::string& tenant);
  void ReleaseStream(const std::string& tenant);

  // Of the memory budget: loaded meshes and unloaded ones streams still use, loads in progress,
  // streams' holds.
  std::size_t memory_bytes_used() const;
  std::size_t memory_bytes_reserved() const;
  std::size_t memory_bytes_streams() const;
  int loads_in_progress() const;

 private:
  // Per tenant: slots held by loads in progress, loaded meshes, open streams, their memory.
  struct Usage {
    int reserved = 0;
    int loaded = 0;
    int streams = 0;
    std::size_t memory_bytes = 0;           // of loaded meshes and unloaded ones still in use
    std::size_t reserved_memory_bytes = 0;  // held by loads in progress
    std::size_t stream_memory_bytes = 0;    // held by streams
  };
  void ReleaseSlot(const std::string& tenant, std::size_t memory_bytes) DEFORM_EXCLUDES(mutex_);
  void ReleaseSlotLocked(const std::string& tenant, std::size_t memory_bytes)
      DEFORM_REQUIRES(mutex_);
  // OK when `bytes` fit in the budgets besides what is in use, not counting `held` (what the
  // caller's own slot or hold counts already).
  Status CheckMemoryLocked(std::size_t bytes, std::size_t held, const std::string& tenant,
                           const std::string& what) const DEFORM_REQUIRES(mutex_);
  Status ResizeHold(MemoryHold* hold, std::size_t bytes, const std::string& what)
      DEFORM_EXCLUDES(mutex_);

  const ServiceLimits limits_;
  mutable Mutex mutex_;
  std::map<std::string, Usage> tenants_ DEFORM_GUARDED_BY(mutex_);
  int reserved_ DEFORM_GUARDED_BY(mutex_) = 0;  // slots held by loads in progress
  int loaded_ DEFORM_GUARDED_BY(mutex_) = 0;    // meshes admitted and not unloaded
  int streams_ DEFORM_GUARDED_BY(mutex_) = 0;
  // memory_bytes of loaded meshes, and of unloaded meshes whose streams have not all ended
  std::size_t memory_used_ DEFORM_GUARDED_BY(mutex_) = 0;
  std::size_t memory_retained_ DEFORM_GUARDED_BY(mutex_) = 0;  // of the latter alone
  std::size_t memory_reserved_ DEFORM_GUARDED_BY(mutex_) = 0;  // held by mesh slots
  std::size_t memory_streams_ DEFORM_GUARDED_BY(mutex_) = 0;   // held by MemoryHolds
};

}  // namespace deform::service
