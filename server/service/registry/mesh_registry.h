// The loaded meshes: ids, their deformation models and what they were loaded with.
//
// A MeshEntry is immutable once registered except for two atomics (unloaded, open_streams), which
// change only under the registry's lock (readers may read them without).
// Streams hold a shared_ptr to their entry, which keeps the model alive after UnloadMesh.
//
// What may be loaded is Admission's (access/admission.h): a load holds a MeshSlot while it runs,
// Register turns it into the mesh's place in the budgets, and a registered mesh's memory_bytes
// stay counted until it is unloaded and the last stream using it has ended (AttachStream /
// DetachStream): a model kept alive by streams after UnloadMesh still counts.
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
#include "core/constraints/skin_constraints.h"
#include "core/model/deformation_model.h"
#include "service/access/admission.h"
#include "service/access/identity.h"
#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"
#include "service/workers/mesh_solve_plan.h"

namespace deform::service {

// What a mesh's file says beyond the solve's mesh: the order clients see its vertices in, units,
// up axis (from a glTF rig; empty for the other formats).
struct MeshFileMetadata {
  // Per vertex in the file's order (the order of frames, rest positions and vertex indices in the
  // API), its vertex of the solved mesh (every entry one of them: RigImport); empty when they are
  // the same.
  std::vector<int> file_vertex_to_mesh;
  // Of those, the ones no triangle uses (ascending): GetMeshInfo's triangles never name them, and
  // the summary warns of them.
  std::vector<int> unused_file_vertices;
  std::string units;
  std::string up_axis;
  std::vector<std::string> warnings;  // the file's (RigImport::warnings), for the summary
};

// What a mesh's frames keep beyond the method's energy (core/constraints/skin_constraints.h).
struct MeshConstraints {
  // Made for the entry's model (it keeps a pointer to it: the entry holds both, this one
  // released first). Null when there are neither bone surfaces nor a volume to keep: frames are
  // then the model's own and carry no FrameConstraints.
  std::shared_ptr<const SkinConstraints> constraints;
  // What the load asked for (MethodOptions.constraints): contacts on is
  // ConstraintOptions::contacts().
  ConstraintOptions options;
  // The estimate of what the bone surfaces, their search trees and the constraints hold.
  std::size_t bytes = 0;
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
  MeshFileMetadata file_metadata;
  // How its frames are solved on the workers (batch scratches, parallel plan; in memory_bytes).
  MeshSolvePlan solve;
  // Declared after `model`, whose lifetime the constraints share (in memory_bytes).
  MeshConstraints constraints;
  // The bone surfaces frames carry transforms for (constraints' bones), or null.
  const BoneContacts* bones() const {
    return constraints.constraints != nullptr ? constraints.constraints->bones() : nullptr;
  }

  // Vertices of frames and rest positions as clients see them (the file's).
  int client_vertex_count() const {
    return file_metadata.file_vertex_to_mesh.empty()
               ? model->mesh().num_vertices()
               : static_cast<int>(file_metadata.file_vertex_to_mesh.size());
  }

  mutable std::atomic<bool> unloaded{false};
  mutable std::atomic<int> open_streams{0};
};

class MeshRegistry {
 public:
  // Meshes are admitted by `admission`, which must outlive the registry.
  explicit MeshRegistry(Admission* admission) : admission_(admission) {}
  MeshRegistry(const MeshRegistry&) = delete;
  MeshRegistry& operator=(const MeshRegistry&) = delete;

  // Registers a built model using `slot` (valid), owned by the slot's tenant and solved with
  // `solve` (PlanMeshSolve), under `id` if given (a mesh restored from a store keeps its id; an id
  // already loaded is INVALID_ARGUMENT), else under a new NewMeshId(), with `constraints` made
  // for `model`. RESOURCE_EXHAUSTED when the mesh does not fit in the memory budget
  // (Admission::AdmitMesh). The slot is released on every error.
  StatusOr<std::shared_ptr<const MeshEntry>> Register(Admission::MeshSlot slot, std::string name,
                                                      std::shared_ptr<const DeformationModel> model,
                                                      MeshFileMetadata file_metadata = {},
                                                      MeshSolvePlan solve = {}, std::string id = {},
                                                      MeshConstraints constraints = {});

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
  // Unscoped (the server's own use: preloads, a load whose client went away, tests).
  StatusOr<std::shared_ptr<const MeshEntry>> Find(const std::string& mesh_id) const;
  std::vector<std::shared_ptr<const MeshEntry>> List() const;
  Status Unload(const std::string& mesh_id);

  int mesh_count() const;
  // Meshes registered since the registry was made (unloaded ones included).
  int registrations() const;
  // Streams attached to any mesh now (every mesh's open_streams together), read without a lock.
  const std::atomic<int>& open_streams() const { return open_streams_; }

 private:
  Admission* const admission_;
  mutable Mutex mutex_;
  // By load order (a sequence number), and the sequence number of each id.
  std::map<std::uint64_t, std::shared_ptr<MeshEntry>> meshes_ DEFORM_GUARDED_BY(mutex_);
  std::unordered_map<std::string, std::uint64_t> order_of_id_ DEFORM_GUARDED_BY(mutex_);
  std::uint64_t next_order_ DEFORM_GUARDED_BY(mutex_) = 1;  // also counts registrations
  std::atomic<int> open_streams_{0};                        // changed under mutex_, read without it
};

}  // namespace deform::service
