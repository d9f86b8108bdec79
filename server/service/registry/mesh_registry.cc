#include "service/registry/mesh_registry.h"

#include <utility>

#include "service/access/audit_log.h"
#include "service/registry/mesh_id.h"

namespace deform::service {
namespace {

Status NotLoaded(const std::string& mesh_id) {
  return Status::NotFound("no mesh with id '" + mesh_id + "' is loaded");
}

const Identity& Unscoped() {
  static const Identity kOperator{"", Role::kOperator, ""};
  return kOperator;
}

}  // namespace

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Register(
    Admission::MeshSlot slot, std::string name, std::shared_ptr<const DeformationModel> model,
    MeshFileMetadata file_metadata, MeshSolvePlan solve, std::string id,
    MeshConstraints constraints) {
  auto entry = std::make_shared<MeshEntry>();
  entry->name = std::move(name);
  entry->tenant = slot.tenant();
  entry->precompute_ms = model->precompute_seconds() * 1e3;
  entry->factor_ms = model->default_factorization()->factor_seconds() * 1e3;
  entry->factor_bytes = model->default_factorization()->factor().bytes();
  // The solve plan's buffers were allocated before the budget check below (which then counts
  // them): for a moment the mesh's memory may exceed its slot's by these, a few right-hand sides
  // per worker. The file-order maps (4 bytes per file vertex, and per unused one) and the
  // constraints are the mesh's too.
  entry->memory_bytes = model->EstimatedBytes() + solve.bytes + constraints.bytes +
                        sizeof(int) * (file_metadata.file_vertex_to_mesh.size() +
                                       file_metadata.unused_file_vertices.size());
  entry->model = std::move(model);
  entry->file_metadata = std::move(file_metadata);
  entry->solve = std::move(solve);
  entry->constraints = std::move(constraints);

  MutexLock lock(&mutex_);
  if (!id.empty() && order_of_id_.count(id) != 0) {
    return Status::InvalidArgument("mesh id '" + id + "' is already loaded");
  }
  DEFORM_RETURN_IF_ERROR(admission_->AdmitMesh(std::move(slot), entry->memory_bytes));
  if (id.empty()) {
    do id = NewMeshId();
    while (order_of_id_.count(id) != 0);
  }
  entry->id = std::move(id);
  const std::uint64_t order = next_order_++;
  order_of_id_.emplace(entry->id, order);
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
  AuditCrossTenant(caller, entry->tenant, mesh_id, "find");
  return std::shared_ptr<const MeshEntry>(entry);
}

std::vector<std::shared_ptr<const MeshEntry>> MeshRegistry::List(const Identity& caller) const {
  MutexLock lock(&mutex_);
  std::vector<std::shared_ptr<const MeshEntry>> list;
  list.reserve(meshes_.size());
  for (const auto& [order, entry] : meshes_) {
    if (!caller.CanAccess(entry->tenant)) continue;
    AuditCrossTenant(caller, entry->tenant, entry->id, "list");
    list.push_back(entry);
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
  AuditCrossTenant(caller, entry.tenant, mesh_id, "unload");
  entry.unloaded.store(true);
  // Its memory stays counted until its last stream detaches.
  admission_->MeshUnloaded(entry.tenant, entry.memory_bytes, entry.open_streams.load() != 0);
  order_of_id_.erase(order);
  meshes_.erase(it);
  return Status::Ok();
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
    admission_->ReleaseUnloadedMesh(entry.tenant, entry.memory_bytes);
  }
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Find(const std::string& mesh_id) const {
  return Find(mesh_id, Unscoped());
}

std::vector<std::shared_ptr<const MeshEntry>> MeshRegistry::List() const {
  return List(Unscoped());
}

Status MeshRegistry::Unload(const std::string& mesh_id) { return Unload(mesh_id, Unscoped()); }

int MeshRegistry::registrations() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(next_order_ - 1);
}

int MeshRegistry::mesh_count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(meshes_.size());
}

}  // namespace deform::service
