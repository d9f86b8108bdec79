// Turns a parsed mesh and skeleton into a registered deformation model, reporting the stages a
// LoadMesh client sees. Shared by the LoadMesh RPC and the server's --preload flags.
//
// Runs for as long as the precomputation takes (about a second per 100k vertices): call it on a
// worker thread, never on a gRPC thread. Thread-safe; `progress` is called on the calling thread.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/base/cancel_token.h"
#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"
#include "core/model/deformation_model.h"
#include "service/mesh_registry.h"
#include "service/service_metrics.h"

namespace deform::service {

enum class LoadStage {
  kValidated,   // mesh and skeleton checked
  kWeights,     // weights, regions and symbolic analysis done
  kFactorised,  // first numeric factorisation done
};

// `elapsed_ms` is measured from the `start` given to BuildAndRegister. Each stage is reported as
// it completes, on the thread running BuildAndRegister.
using LoadProgress = std::function<void(LoadStage stage, double elapsed_ms)>;

struct LoadJob {
  std::string name;
  std::string id;  // empty: a new id (MeshRegistry::Register); a stored mesh's own id on restore
  TriangleMesh mesh;
  Skeleton skeleton;
  ModelOptions options;  // options.limits.max_vertices is set from the registry's limits
  std::optional<SkinWeights> weights;  // a rig's own weights: binding from them (Build)
  MeshPresentation presentation;       // from a glTF rig: the file's vertex order, units, up axis
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  // Stops the build between its phases once cancelled (BuildHooks::cancel); null: never. Must
  // outlive BuildAndRegister.
  const CancelToken* cancel = nullptr;
  // Where the build's duration is counted (ServiceMetrics::BuildFinished); null: nowhere. Must
  // outlive BuildAndRegister.
  ServiceMetrics* metrics = nullptr;
};

// Builds the model and registers it with `reservation`. Checks nothing the core checks: the mesh
// readers validated an uploaded mesh, and DeformationModel::Build validates mesh and options again
// (with the registry's vertex limit in options.limits); once it has, `reservation` is made to hold
// the model's estimate from the mesh's size (DeformationModel::EstimateBytesBeforeBuild,
// MeshRegistry::ReserveMemory) before anything of the model is allocated, and kValidated reported.
// Errors: INVALID_ARGUMENT for a bad mesh or options (naming the problem), RESOURCE_EXHAUSTED for
// limits.
StatusOr<std::shared_ptr<const MeshEntry>> BuildAndRegister(MeshRegistry* registry,
                                                            MeshRegistry::Reservation reservation,
                                                            LoadJob job,
                                                            const LoadProgress& progress = {});

}  // namespace deform::service
