#include "service/mesh_registry.h"

#include <utility>

#include "service/mesh_id.h"

namespace deform::service {
namespace {

std::string MebiBytes(std::size_t bytes) {
  return std::to_string((bytes + (std::size_t{1} << 20) - 1) >> 20) + " MiB";
}

Status NotLoaded(const std::string& mesh_id) {
  return Status::NotFound("no mesh with id '" + mesh_id + "' is loaded");
}

const Identity& Unscoped() {
  static const Identity kOperator{"", Role::kOperator};
  return kOperator;
}

}  // namespace

MeshRegistry::Reservation::Reservation(Reservation&& other) noexcept
    : registry_(std::exchange(other.registry_, nullptr)),
      tenant_(std::move(other.tenant_)),
      memory_bytes_(std::exchange(other.memory_bytes_, 0)) {}

MeshRegistry::Reservation& MeshRegistry::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    Release();
    registry_ = std::exchange(other.registry_, nullptr);
    tenant_ = std::move(other.tenant_);
    memory_bytes_ = std::exchange(other.memory_bytes_, 0);
  }
  return *this;
}

MeshRegistry::Reservation::~Reservation() { Release(); }

void MeshRegistry::Reservation::Release() {
  if (registry_ != nullptr) {
    std::exchange(registry_, nullptr)->ReleaseSlot(tenant_, std::exchange(memory_bytes_, 0));
  }
}

MeshRegistry::MemoryHold::MemoryHold(MemoryHold&& other) noexcept
    : registry_(std::exchange(other.registry_, nullptr)),
      tenant_(std::move(other.tenant_)),
      bytes_(std::exchange(other.bytes_, 0)) {}

MeshRegistry::MemoryHold& MeshRegistry::MemoryHold::operator=(MemoryHold&& other) noexcept {
  if (this != &other) {
    if (registry_ != nullptr) (void)Resize(0, "");
    registry_ = std::exchange(other.registry_, nullptr);
    tenant_ = std::move(other.tenant_);
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}

MeshRegistry::MemoryHold::~MemoryHold() {
  if (registry_ != nullptr) (void)Resize(0, "");
}

Status MeshRegistry::MemoryHold::Resize(std::size_t bytes, const std::string& what) {
  if (registry_ == nullptr) return Status::FailedPrecondition("an empty memory hold");
  MeshRegistry& registry = *registry_;
  MutexLock lock(&registry.mutex_);
  if (bytes > bytes_) {
    DEFORM_RETURN_IF_ERROR(registry.CheckMemoryLocked(bytes, bytes_, tenant_, what));
  }
  TenantUsage& usage = registry.tenants_[tenant_];
  registry.memory_streams_ = registry.memory_streams_ - bytes_ + bytes;
  usage.stream_memory_bytes = usage.stream_memory_bytes - bytes_ + bytes;
  bytes_ = bytes;
  return Status::Ok();
}

MeshRegistry::MeshRegistry(const ServiceLimits& limits, SolveSettings solve_settings)
    : limits_(limits), solve_settings_(solve_settings) {}

MeshRegistry::MemoryHold MeshRegistry::HoldMemory(const std::string& tenant) {
  return MemoryHold(this, tenant);
}

StatusOr<MeshRegistry::Reservation> MeshRegistry::Reserve(const std::string& tenant) {
  MutexLock lock(&mutex_);
  const int in_use = static_cast<int>(meshes_.size()) + reserved_;
  if (in_use >= limits_.max_meshes) {
    return Status::ResourceExhausted("mesh limit reached: " + std::to_string(meshes_.size()) +
                                     " loaded and " + std::to_string(reserved_) +
                                     " loading, of at most " + std::to_string(limits_.max_meshes) +
                                     " (unload a mesh first)");
  }
  TenantUsage& usage = tenants_[tenant];
  if (limits_.tenant_max_meshes > 0 && usage.loaded + usage.reserved >= limits_.tenant_max_meshes) {
    return Status::ResourceExhausted(
        "tenant mesh limit reached (--tenant-max-meshes): " + std::to_string(usage.loaded) +
        " loaded and " + std::to_string(usage.reserved) + " loading, of at most " +
        std::to_string(limits_.tenant_max_meshes) + " per tenant (unload a mesh first)");
  }
  ++reserved_;
  ++usage.reserved;
  return Reservation(this, tenant);
}

void MeshRegistry::ReleaseSlot(const std::string& tenant, std::size_t memory_bytes) {
  MutexLock lock(&mutex_);
  TenantUsage& usage = tenants_[tenant];
  --reserved_;
  --usage.reserved;
  memory_reserved_ -= memory_bytes;
  usage.reserved_memory_bytes -= memory_bytes;
}

Status MeshRegistry::CheckMemoryLocked(std::size_t bytes, std::size_t held,
                                       const std::string& tenant, const std::string& what) const {
  const std::size_t in_use = memory_used_ + memory_reserved_ + memory_streams_ - held;
  if (bytes > limits_.max_memory_bytes || in_use > limits_.max_memory_bytes - bytes) {
    return Status::ResourceExhausted(
        "memory budget exceeded (--max-memory-mb): " + what + " needs about " + MebiBytes(bytes) +
        ", " + MebiBytes(in_use) + " of the " + MebiBytes(limits_.max_memory_bytes) +
        " budget are in use (" + MebiBytes(memory_used_ - memory_retained_) +
        " by loaded meshes, " + MebiBytes(memory_retained_) +
        " by unloaded meshes that streams still use, " + MebiBytes(memory_streams_) +
        " by streams' buffers and factorisations)");
  }
  if (limits_.tenant_max_memory_bytes > 0) {
    const auto it = tenants_.find(tenant);
    const std::size_t used = it == tenants_.end()
                                 ? 0
                                 : it->second.memory_bytes + it->second.reserved_memory_bytes +
                                       it->second.stream_memory_bytes - held;
    if (bytes > limits_.tenant_max_memory_bytes || used > limits_.tenant_max_memory_bytes - bytes) {
      return Status::ResourceExhausted(
          "tenant memory budget exceeded (--tenant-max-memory-mb): " + what + " needs about " +
          MebiBytes(bytes) + ", " + MebiBytes(used) + " of the tenant's " +
          MebiBytes(limits_.tenant_max_memory_bytes) + " are in use");
    }
  }
  return Status::Ok();
}

Status MeshRegistry::ReserveMemory(Reservation* reservation, std::size_t bytes,
                                   const std::string& what) {
  MutexLock lock(&mutex_);
  const std::size_t held = reservation->memory_bytes_;
  DEFORM_RETURN_IF_ERROR(CheckMemoryLocked(bytes, held, reservation->tenant_, what));
  TenantUsage& usage = tenants_[reservation->tenant_];
  memory_reserved_ = memory_reserved_ - held + bytes;
  usage.reserved_memory_bytes = usage.reserved_memory_bytes - held + bytes;
  reservation->memory_bytes_ = bytes;
  return Status::Ok();
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Register(
    Reservation reservation, std::string name, std::shared_ptr<const DeformationModel> model,
    MeshPresentation presentation, std::string id) {
  auto entry = std::make_shared<MeshEntry>();
  entry->name = std::move(name);
  entry->tenant = reservation.tenant();
  entry->precompute_ms = model->precompute_seconds() * 1e3;
  entry->factor_ms = model->default_factorization()->factor_seconds() * 1e3;
  entry->factor_bytes = model->default_factorization()->factor().bytes();
  entry->memory_bytes = model->EstimatedBytes();
  // Allocated before the budget check below (which then counts it): for a moment the mesh's
  // memory may exceed its reservation by these buffers, a few right-hand sides per worker.
  // A linear response evaluates each frame alone: nothing to batch or split.
  const bool solves = model->default_factorization()->linear_response() == nullptr;
  if (solves && solve_settings_.slots >= 2 &&
      entry->factor_bytes >= solve_settings_.parallel_min_factor_bytes) {
    auto plan = std::make_unique<ParallelSolvePlan>(
        model->default_factorization()->factor().PlanParallel(solve_settings_.slots));
    if (plan->parts >= 2) entry->parallel_plan = std::move(plan);
  }
  if (solves && solve_settings_.max_frames >= 2 && solve_settings_.slots > 0) {
    entry->batch_scratches = std::make_unique<BatchScratchPool>(
        *model, solve_settings_.slots, solve_settings_.max_frames, entry->parallel_plan.get());
    entry->memory_bytes += BatchScratchPool::Bytes(
        *model, solve_settings_.slots, solve_settings_.max_frames, entry->parallel_plan.get());
  }
  entry->model = std::move(model);
  // The file-order maps (4 bytes per file vertex, and per unused one) are the mesh's too.
  entry->memory_bytes += sizeof(int) * (presentation.file_vertex_to_mesh.size() +
                                        presentation.unused_file_vertices.size());
  entry->presentation = std::move(presentation);

  MutexLock lock(&mutex_);
  // From here the reservation's slot is released here (failure) or becomes the mesh's.
  reservation.registry_ = nullptr;
  const std::size_t held = std::exchange(reservation.memory_bytes_, 0);
  TenantUsage& usage = tenants_[entry->tenant];
  --reserved_;
  --usage.reserved;
  memory_reserved_ -= held;
  usage.reserved_memory_bytes -= held;
  DEFORM_RETURN_IF_ERROR(CheckMemoryLocked(entry->memory_bytes, 0, entry->tenant, "the mesh"));
  if (!id.empty() && order_of_id_.count(id) != 0) {
    return Status::InvalidArgument("mesh id '" + id + "' is already loaded");
  }
  if (id.empty()) {
    do id = NewMeshId();
    while (order_of_id_.count(id) != 0);
  }
  entry->id = std::move(id);
  const std::uint64_t order = next_order_++;
  order_of_id_.emplace(entry->id, order);
  memory_used_ += entry->memory_bytes;
  ++usage.loaded;
  usage.memory_bytes += entry->memory_bytes;
  meshes_.emplace(order, entry);
  return std::shared_ptr<const MeshEntry>(std::move(entry));
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Find(const std::string& mesh_id,
                                                              const Identity& caller) const {
  MutexLock lock(&mutex_);
  const auto order = order_of_id_.find(mesh_id);
  if (order == order_of_id_.end()) return NotLoaded(mesh_id);
  const std::shared_ptr<MeshEntry>& entry = meshes_.at(order->second);
  if (!caller.CanAccess(entry->tenant)) return NotLoaded(mesh_id);
  return std::shared_ptr<const MeshEntry>(entry);
}

std::vector<std::shared_ptr<const MeshEntry>> MeshRegistry::List(const Identity& caller) const {
  MutexLock lock(&mutex_);
  std::vector<std::shared_ptr<const MeshEntry>> list;
  list.reserve(meshes_.size());
  for (const auto& [order, entry] : meshes_) {
    if (caller.CanAccess(entry->tenant)) list.push_back(entry);
  }
  return list;
}

Status MeshRegistry::Unload(const std::string& mesh_id, const Identity& caller) {
  MutexLock lock(&mutex_);
  const auto order = order_of_id_.find(mesh_id);
  if (order == order_of_id_.end()) return NotLoaded(mesh_id);
  const auto it = meshes_.find(order->second);
  MeshEntry& entry = *it->second;
  if (!caller.CanAccess(entry.tenant)) return NotLoaded(mesh_id);
  entry.unloaded.store(true);
  --tenants_[entry.tenant].loaded;
  if (entry.open_streams.load() == 0) {
    ReleaseMemoryLocked(entry);
  } else {
    memory_retained_ += entry.memory_bytes;  // until its last stream detaches
  }
  order_of_id_.erase(order);
  meshes_.erase(it);
  return Status::Ok();
}

void MeshRegistry::ReleaseMemoryLocked(const MeshEntry& entry) {
  memory_used_ -= entry.memory_bytes;
  tenants_[entry.tenant].memory_bytes -= entry.memory_bytes;
}

Status MeshRegistry::AttachStream(const MeshEntry& entry) {
  MutexLock lock(&mutex_);
  if (entry.unloaded.load()) return NotLoaded(entry.id);
  entry.open_streams.fetch_add(1);
  open_streams_.fetch_add(1);
  return Status::Ok();
}

void MeshRegistry::DetachStream(const MeshEntry& entry) {
  MutexLock lock(&mutex_);
  open_streams_.fetch_sub(1);
  if (entry.open_streams.fetch_sub(1) == 1 && entry.unloaded.load()) {
    memory_retained_ -= entry.memory_bytes;
    ReleaseMemoryLocked(entry);
  }
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Find(const std::string& mesh_id) const {
  return Find(mesh_id, Unscoped());
}

std::vector<std::shared_ptr<const MeshEntry>> MeshRegistry::List() const {
  return List(Unscoped());
}

Status MeshRegistry::Unload(const std::string& mesh_id) { return Unload(mesh_id, Unscoped()); }

std::size_t MeshRegistry::memory_bytes_used() const {
  MutexLock lock(&mutex_);
  return memory_used_;
}

std::size_t MeshRegistry::memory_bytes_reserved() const {
  MutexLock lock(&mutex_);
  return memory_reserved_;
}

std::size_t MeshRegistry::memory_bytes_streams() const {
  MutexLock lock(&mutex_);
  return memory_streams_;
}

int MeshRegistry::loads_in_progress() const {
  MutexLock lock(&mutex_);
  return reserved_;
}

int MeshRegistry::registrations() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(next_order_ - 1);
}

int MeshRegistry::mesh_count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(meshes_.size());
}

}  // namespace deform::service
