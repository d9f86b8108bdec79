#include "service/mesh_registry.h"

#include <charconv>
#include <optional>
#include <string_view>
#include <utility>

namespace deform::service {
namespace {

constexpr std::string_view kIdPrefix = "mesh-";

std::optional<std::uint64_t> NumberOfId(std::string_view id) {
  if (id.substr(0, kIdPrefix.size()) != kIdPrefix) return std::nullopt;
  id.remove_prefix(kIdPrefix.size());
  std::uint64_t number = 0;
  const auto [end, error] = std::from_chars(id.data(), id.data() + id.size(), number);
  if (error != std::errc() || end != id.data() + id.size() || id.empty()) return std::nullopt;
  return number;
}

std::string MebiBytes(std::size_t bytes) {
  return std::to_string((bytes + (std::size_t{1} << 20) - 1) >> 20) + " MiB";
}

}  // namespace

MeshRegistry::Reservation::Reservation(Reservation&& other) noexcept
    : registry_(std::exchange(other.registry_, nullptr)) {}

MeshRegistry::Reservation& MeshRegistry::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    Release();
    registry_ = std::exchange(other.registry_, nullptr);
  }
  return *this;
}

MeshRegistry::Reservation::~Reservation() { Release(); }

void MeshRegistry::Reservation::Release() {
  if (registry_ != nullptr) std::exchange(registry_, nullptr)->ReleaseSlot();
}

MeshRegistry::MeshRegistry(const ServiceLimits& limits) : limits_(limits) {}

StatusOr<MeshRegistry::Reservation> MeshRegistry::Reserve() {
  MutexLock lock(&mutex_);
  const int in_use = static_cast<int>(meshes_.size()) + reserved_;
  if (in_use >= limits_.max_meshes) {
    return Status::ResourceExhausted("mesh limit reached: " + std::to_string(meshes_.size()) +
                                     " loaded and " + std::to_string(reserved_) +
                                     " loading, of at most " + std::to_string(limits_.max_meshes) +
                                     " (unload a mesh first)");
  }
  ++reserved_;
  return Reservation(this);
}

void MeshRegistry::ReleaseSlot() {
  MutexLock lock(&mutex_);
  --reserved_;
}

Status MeshRegistry::CheckMemoryAvailable(std::size_t bytes) const {
  MutexLock lock(&mutex_);
  if (memory_used_ + bytes > limits_.max_memory_bytes) {
    return Status::ResourceExhausted("memory budget exceeded: the mesh needs about " +
                                     MebiBytes(bytes) + ", " + MebiBytes(memory_used_) +
                                     " of the " + MebiBytes(limits_.max_memory_bytes) +
                                     " budget are in use");
  }
  return Status::Ok();
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Register(
    Reservation reservation, std::string name, std::shared_ptr<const DeformationModel> model,
    MeshPresentation presentation) {
  auto entry = std::make_shared<MeshEntry>();
  entry->name = std::move(name);
  entry->precompute_ms = model->precompute_seconds() * 1e3;
  entry->factor_ms = model->default_factorization()->factor_seconds() * 1e3;
  entry->factor_bytes = model->default_factorization()->factor().bytes();
  entry->memory_bytes = model->EstimatedBytes();
  entry->model = std::move(model);
  entry->presentation = std::move(presentation);

  MutexLock lock(&mutex_);
  if (memory_used_ + entry->memory_bytes > limits_.max_memory_bytes) {
    const Status status = Status::ResourceExhausted(
        "memory budget exceeded: the mesh needs about " + MebiBytes(entry->memory_bytes) + ", " +
        MebiBytes(memory_used_) + " of the " + MebiBytes(limits_.max_memory_bytes) +
        " budget are in use");
    --reserved_;
    reservation.registry_ = nullptr;
    return status;
  }
  const std::uint64_t number = next_number_++;
  entry->id = std::string(kIdPrefix) + std::to_string(number);
  memory_used_ += entry->memory_bytes;
  // The reservation's slot becomes the loaded mesh's slot.
  --reserved_;
  reservation.registry_ = nullptr;
  meshes_.emplace(number, entry);
  return std::shared_ptr<const MeshEntry>(std::move(entry));
}

StatusOr<std::shared_ptr<const MeshEntry>> MeshRegistry::Find(const std::string& mesh_id) const {
  const std::optional<std::uint64_t> number = NumberOfId(mesh_id);
  MutexLock lock(&mutex_);
  if (number) {
    const auto it = meshes_.find(*number);
    if (it != meshes_.end()) return std::shared_ptr<const MeshEntry>(it->second);
  }
  return Status::NotFound("no mesh with id '" + mesh_id + "' is loaded");
}

std::vector<std::shared_ptr<const MeshEntry>> MeshRegistry::List() const {
  MutexLock lock(&mutex_);
  std::vector<std::shared_ptr<const MeshEntry>> list;
  list.reserve(meshes_.size());
  for (const auto& [number, entry] : meshes_) list.push_back(entry);
  return list;
}

Status MeshRegistry::Unload(const std::string& mesh_id) {
  const std::optional<std::uint64_t> number = NumberOfId(mesh_id);
  MutexLock lock(&mutex_);
  const auto it = number ? meshes_.find(*number) : meshes_.end();
  if (it == meshes_.end()) return Status::NotFound("no mesh with id '" + mesh_id + "' is loaded");
  it->second->unloaded.store(true);
  memory_used_ -= it->second->memory_bytes;
  meshes_.erase(it);
  return Status::Ok();
}

std::size_t MeshRegistry::memory_bytes_used() const {
  MutexLock lock(&mutex_);
  return memory_used_;
}

int MeshRegistry::mesh_count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(meshes_.size());
}

}  // namespace deform::service
