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
#include "service/base/service_options.h"
#include "service/load/mesh_loader.h"

namespace deform::service {

// The job for `header` and `*mesh_bytes` (consumed: emptied once parsed). The name defaults to
// "phantom:N" or "upload". INVALID_ARGUMENT naming the part (mesh, skeleton, weights, glTF,
// options) for bad input, RESOURCE_EXHAUSTED for the vertex limit.
StatusOr<LoadJob> LoadJobFromRequest(const v1::LoadMeshHeader& header, std::string* mesh_bytes,
                                     const ServiceLimits& limits);

// The memory a load of `header` with `mesh_bytes` needs, as far as the file declares before it is
// parsed (declared_mesh_size.h: OFF and PLY headers, STL's count, OBJ's lines): the model's
// estimate for the declared size (DeformationModel::EstimateBytesBeforeBuild) plus the bytes
// themselves, held while they are parsed. RESOURCE_EXHAUSTED naming --max-vertices when the file
// declares more vertices than `limits` allow; 0 for a phantom, a glTF rig or a file that declares
// nothing readable (its parsed size is checked before the build instead). `subject` receives how
// the refusal would name it.
StatusOr<std::size_t> DeclaredLoadBytes(const v1::LoadMeshHeader& header,
                                        const std::string& mesh_bytes, const ServiceLimits& limits,
                                        std::string* subject);

}  // namespace deform::service
