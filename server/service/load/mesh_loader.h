// Turns a parsed mesh and skeleton into a registered deformation model, reporting the stages a
// LoadMesh client sees. Shared by the LoadMesh RPC and the server's --preload flags.
//
// Runs for as long as the precomputation takes (it grows with the mesh: docs/performance.md, "Time
// to first frame"): call it on a worker thread, never on a gRPC thread. Thread-safe; `progress` is
// called on the calling thread.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/base/cancel_token.h"
#include "core/base/status.h"
#include "core/constraints/skin_constraints.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"
#include "core/model/deformation_model.h"
#include "service/context/service_context.h"
#include "service/metrics/service_metrics.h"
#include "service/registry/mesh_registry.h"

namespace deform::service {

enum class LoadStage {
  kValidated,   // mesh and skeleton checked
  kWeights,     // weights, regions and symbolic analysis done
  kFactorized,  // first numeric factorization done
};

// `elapsed_ms` is measured from the `start` given to BuildAndRegister. Each stage is reported as
// it completes, on the thread running BuildAndRegister.
using LoadProgress = std::function<void(LoadStage stage, double elapsed_ms)>;

struct LoadJob {
  std::string name;
  std::string id;  // empty: a new id (MeshRegistry::Register); a stored mesh's own id on restore
  TriangleMesh mesh;
  Skeleton skeleton;
  ModelOptions options;  // options.limits.max_vertices is set from the context's limits
  std::optional<SkinWeights> weights;  // a rig's own weights: binding from them (Build)
  MeshFileMetadata file_metadata;      // from a glTF rig: the file's vertex order, units, up axis
  // Bone surfaces (the phantom's, an upload's) in the solved mesh's frame, bones resolved and
  // checked against the skeleton (ValidateBoneSurfaces); the build refuses one the rest skin
  // enters (BoneContacts::Create).
  std::vector<BoneSurface> bone_surfaces;
  ConstraintOptions constraints;  // MethodOptions.constraints
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  // Stops the build between its phases once cancelled (BuildHooks::cancel); null: never. Must
  // outlive BuildAndRegister.
  const CancelToken* cancel = nullptr;
  // Where the build's duration is counted (ServiceMetrics::BuildFinished); null: nowhere. Must
  // outlive BuildAndRegister.
  ServiceMetrics* metrics = nullptr;
};

// Builds the model, plans its solve on the workers (PlanMeshSolve with the context's
// SolveSettings) and registers it with `slot`. Checks nothing the core checks: the mesh readers
// validated an uploaded mesh, and DeformationModel::Build validates mesh and options again (with
// the context's vertex limit in options.limits); once it has, `slot` is made to hold the model's
// estimate from the mesh's size (DeformationModel::EstimateBytesBeforeBuild,
// Admission::ReserveMemory) before anything of the model is allocated, and kValidated reported.
// Errors: INVALID_ARGUMENT for a bad mesh or options (naming the problem), RESOURCE_EXHAUSTED for
// limits.
StatusOr<std::shared_ptr<const MeshEntry>> BuildAndRegister(ServiceContext* context,
                                                            Admission::MeshSlot slot, LoadJob job,
                                                            const LoadProgress& progress = {});

}  // namespace deform::service
