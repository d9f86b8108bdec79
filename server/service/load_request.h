// A LoadMesh request (its header and the uploaded mesh bytes) into a LoadJob: the phantom built,
// or the upload's mesh, skeleton and weights parsed (a glTF rig gives all three), the method
// options converted. Shared by the LoadMesh RPC and the restore of stored meshes (mesh_store.h),
// so that a restored mesh is built exactly as it was loaded. Thread-safe (no shared state).
#pragma once

#include <string>

#include "core/base/status.h"
#include "core/io/mesh_io.h"
#include "core/io/skin_weights_io.h"
#include "deform/v1/deform.pb.h"
#include "service/mesh_loader.h"
#include "service/service_options.h"

namespace deform::service {

// The job for `header` and `*mesh_bytes` (consumed: emptied once parsed). The name defaults to
// "phantom:N" or "upload". INVALID_ARGUMENT naming the part (mesh, skeleton, weights, glTF,
// options) for bad input, RESOURCE_EXHAUSTED for the vertex limit.
StatusOr<LoadJob> LoadJobFromRequest(const v1::LoadMeshHeader& header, std::string* mesh_bytes,
                                     const ServiceLimits& limits);

}  // namespace deform::service
