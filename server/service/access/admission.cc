#include "service/access/admission.h"

#include <utility>

namespace deform::service {
namespace {

std::string MebiBytes(std::size_t bytes) {
  return std::to_string((bytes + (std::size_t{1} << 20) - 1) >> 20) + " MiB";
}

// The scope a per-tenant refusal names (QuotaFailure's subject, status_mapping.h).
std::string TenantScope(const std::string& tenant) { return "tenant:" + tenant; }

}  // namespace

Admission::MeshSlot::MeshSlot(MeshSlot&& other) noexcept
    : admission_(std::exchange(other.admission_, nullptr)),
      tenant_(std::move(other.tenant_)),
      memory_bytes_(std::exchange(other.memory_bytes_, 0)) {}

Admission::MeshSlot& Admission::MeshSlot::operator=(MeshSlot&& other) noexcept {
  if (this != &other) {
    Release();
    admission_ = std::exchange(other.admission_, nullptr);
    tenant_ = std::move(other.tenant_);
    memory_bytes_ = std::exchange(other.memory_bytes_, 0);
  }
  return *this;
}

Admission::MeshSlot::~MeshSlot() { Release(); }

void Admission::MeshSlot::Release() {
  if (admission_ != nullptr) {
    std::exchange(admission_, nullptr)->ReleaseSlot(tenant_, std::exchange(memory_bytes_, 0));
  }
}

Admission::MemoryHold::MemoryHold(MemoryHold&& other) noexcept
    : admission_(std::exchange(other.admission_, nullptr)),
      tenant_(std::move(other.tenant_)),
      bytes_(std::exchange(other.bytes_, 0)) {}

Admission::MemoryHold& Admission::MemoryHold::operator=(MemoryHold&& other) noexcept {
  if (this != &other) {
    if (admission_ != nullptr) (void)Resize(0, "");
    admission_ = std::exchange(other.admission_, nullptr);
    tenant_ = std::move(other.tenant_);
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}

Admission::MemoryHold::~MemoryHold() {
  if (admission_ != nullptr) (void)Resize(0, "");
}

Status Admission::MemoryHold::Resize(std::size_t bytes, const std::string& what) {
  if (admission_ == nullptr) return Status::FailedPrecondition("an empty memory hold");
  return admission_->ResizeHold(this, bytes, what);
}

Status Admission::ResizeHold(MemoryHold* hold, std::size_t bytes, const std::string& what) {
  MutexLock lock(&mutex_);
  if (bytes > hold->bytes_) {
    DEFORM_RETURN_IF_ERROR(CheckMemoryLocked(bytes, hold->bytes_, hold->tenant_, what));
  }
  Usage& usage = tenants_[hold->tenant_];
  memory_streams_ = memory_streams_ - hold->bytes_ + bytes;
  usage.stream_memory_bytes = usage.stream_memory_bytes - hold->bytes_ + bytes;
  hold->bytes_ = bytes;
  return Status::Ok();
}

Admission::MemoryHold Admission::HoldMemory(const std::string& tenant) {
  return MemoryHold(this, tenant);
}

StatusOr<Admission::MeshSlot> Admission::ReserveMesh(const std::string& tenant) {
  MutexLock lock(&mutex_);
  if (loaded_ + reserved_ >= limits_.max_meshes) {
    return Status::ResourceExhausted("mesh limit reached: " + std::to_string(loaded_) +
                                     " loaded and " + std::to_string(reserved_) +
                                     " loading, of at most " + std::to_string(limits_.max_meshes) +
                                     " (unload a mesh first)")
        .WithLimit("server", "--max-meshes");
  }
  Usage& usage = tenants_[tenant];
  if (limits_.tenant_max_meshes > 0 && usage.loaded + usage.reserved >= limits_.tenant_max_meshes) {
    return Status::ResourceExhausted(
               "tenant mesh limit reached (--tenant-max-meshes): " + std::to_string(usage.loaded) +
               " loaded and " + std::to_string(usage.reserved) + " loading, of at most " +
               std::to_string(limits_.tenant_max_meshes) + " per tenant (unload a mesh first)")
        .WithLimit(TenantScope(tenant), "--tenant-max-meshes");
  }
  ++reserved_;
  ++usage.reserved;
  return MeshSlot(this, tenant);
}

void Admission::ReleaseSlot(const std::string& tenant, std::size_t memory_bytes) {
  MutexLock lock(&mutex_);
  ReleaseSlotLocked(tenant, memory_bytes);
}

void Admission::ReleaseSlotLocked(const std::string& tenant, std::size_t memory_bytes) {
  Usage& usage = tenants_[tenant];
  --reserved_;
  --usage.reserved;
  memory_reserved_ -= memory_bytes;
  usage.reserved_memory_bytes -= memory_bytes;
}

Status Admission::CheckMemoryLocked(std::size_t bytes, std::size_t held, const std::string& tenant,
                                    const std::string& what) const {
  const std::size_t in_use = memory_used_ + memory_reserved_ + memory_streams_ - held;
  if (bytes > limits_.max_memory_bytes || in_use > limits_.max_memory_bytes - bytes) {
    return Status::ResourceExhausted(
               "memory budget exceeded (--max-memory-mb): " + what + " needs about " +
               MebiBytes(bytes) + ", " + MebiBytes(in_use) + " of the " +
               MebiBytes(limits_.max_memory_bytes) + " budget are in use (" +
               MebiBytes(memory_used_ - memory_retained_) + " by loaded meshes, " +
               MebiBytes(memory_retained_) + " by unloaded meshes that streams still use, " +
               MebiBytes(memory_streams_) + " by streams' buffers and factorizations)")
        .WithLimit("server", "--max-memory-mb");
  }
  if (limits_.tenant_max_memory_bytes > 0) {
    const auto it = tenants_.find(tenant);
    const std::size_t used = it == tenants_.end()
                                 ? 0
                                 : it->second.memory_bytes + it->second.reserved_memory_bytes +
                                       it->second.stream_memory_bytes - held;
    if (bytes > limits_.tenant_max_memory_bytes || used > limits_.tenant_max_memory_bytes - bytes) {
      return Status::ResourceExhausted(
                 "tenant memory budget exceeded (--tenant-max-memory-mb): " + what +
                 " needs about " + MebiBytes(bytes) + ", " + MebiBytes(used) + " of the tenant's " +
                 MebiBytes(limits_.tenant_max_memory_bytes) + " are in use")
          .WithLimit(TenantScope(tenant), "--tenant-max-memory-mb");
    }
  }
  return Status::Ok();
}

Status Admission::ReserveMemory(MeshSlot* slot, std::size_t bytes, const std::string& what) {
  MutexLock lock(&mutex_);
  const std::size_t held = slot->memory_bytes_;
  DEFORM_RETURN_IF_ERROR(CheckMemoryLocked(bytes, held, slot->tenant_, what));
  Usage& usage = tenants_[slot->tenant_];
  memory_reserved_ = memory_reserved_ - held + bytes;
  usage.reserved_memory_bytes = usage.reserved_memory_bytes - held + bytes;
  slot->memory_bytes_ = bytes;
  return Status::Ok();
}

Status Admission::AdmitMesh(MeshSlot slot, std::size_t bytes) {
  MutexLock lock(&mutex_);
  // From here the slot is released here (failure) or becomes the mesh's.
  slot.admission_ = nullptr;
  ReleaseSlotLocked(slot.tenant_, std::exchange(slot.memory_bytes_, 0));
  DEFORM_RETURN_IF_ERROR(CheckMemoryLocked(bytes, 0, slot.tenant_, "the mesh"));
  Usage& usage = tenants_[slot.tenant_];
  ++loaded_;
  ++usage.loaded;
  memory_used_ += bytes;
  usage.memory_bytes += bytes;
  return Status::Ok();
}

void Admission::MeshUnloaded(const std::string& tenant, std::size_t bytes, bool still_in_use) {
  MutexLock lock(&mutex_);
  Usage& usage = tenants_[tenant];
  --loaded_;
  --usage.loaded;
  if (still_in_use) {
    memory_retained_ += bytes;
  } else {
    memory_used_ -= bytes;
    usage.memory_bytes -= bytes;
  }
}

void Admission::ReleaseUnloadedMesh(const std::string& tenant, std::size_t bytes) {
  MutexLock lock(&mutex_);
  memory_retained_ -= bytes;
  memory_used_ -= bytes;
  tenants_[tenant].memory_bytes -= bytes;
}

Status Admission::AcquireStream(const std::string& tenant) {
  MutexLock lock(&mutex_);
  if (limits_.max_streams > 0 && streams_ >= limits_.max_streams) {
    return Status::ResourceExhausted(
               "server stream limit reached (--max-streams): " + std::to_string(streams_) +
               " streams open, of at most " + std::to_string(limits_.max_streams))
        .WithLimit("server", "--max-streams");
  }
  Usage& usage = tenants_[tenant];
  if (limits_.tenant_max_streams > 0 && usage.streams >= limits_.tenant_max_streams) {
    return Status::ResourceExhausted("tenant stream limit reached (--tenant-max-streams): " +
                                     std::to_string(usage.streams) + " streams open, of at most " +
                                     std::to_string(limits_.tenant_max_streams) + " per tenant")
        .WithLimit(TenantScope(tenant), "--tenant-max-streams");
  }
  ++usage.streams;
  ++streams_;
  return Status::Ok();
}

void Admission::ReleaseStream(const std::string& tenant) {
  MutexLock lock(&mutex_);
  const auto it = tenants_.find(tenant);
  if (it == tenants_.end() || it->second.streams == 0) return;
  --it->second.streams;
  --streams_;
}

std::size_t Admission::memory_bytes_used() const {
  MutexLock lock(&mutex_);
  return memory_used_;
}

std::size_t Admission::memory_bytes_reserved() const {
  MutexLock lock(&mutex_);
  return memory_reserved_;
}

std::size_t Admission::memory_bytes_streams() const {
  MutexLock lock(&mutex_);
  return memory_streams_;
}

int Admission::loads_in_progress() const {
  MutexLock lock(&mutex_);
  return reserved_;
}

}  // namespace deform::service
