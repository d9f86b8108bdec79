#include "cli/mesh_source.h"

namespace deform::cli {

std::string MeshSource::Description() const {
  if (!mesh_id.empty()) return mesh_id;
  return mesh_path.empty() ? "phantom" : mesh_path;
}

grpc::Status AcquireMesh(client::DeformClient& client, const MeshSource& source,
                         deform::v1::MeshSummary* summary, bool* loaded) {
  *loaded = false;
  if (!source.mesh_id.empty()) {
    deform::v1::GetMeshInfoResponse info;
    grpc::Status status = client.GetMeshInfo(source.mesh_id, /*include_geometry=*/false, &info);
    if (status.ok()) *summary = info.summary();
    return status;
  }
  deform::v1::MethodOptions options;
  options.set_rotation_blend(source.rotation_blend);
  grpc::Status status =
      source.mesh_path.empty()
          ? client.LoadPhantom(source.phantom_vertices, options, summary)
          : client.LoadMeshFiles(source.mesh_path, source.skeleton_path, options, summary,
                                 /*progress=*/{}, source.weights_path);
  *loaded = status.ok();
  return status;
}

}  // namespace deform::cli
