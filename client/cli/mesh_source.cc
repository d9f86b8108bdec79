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
  if (source.contacts.has_value()) options.mutable_constraints()->set_contacts(*source.contacts);
  if (source.keep_volume.has_value()) {
    options.mutable_constraints()->set_keep_volume(*source.keep_volume);
  }
  grpc::Status status;
  if (source.mesh_path.empty()) {
    deform::v1::LoadMeshHeader header;
    header.set_name("phantom");
    header.mutable_phantom()->set_vertices(source.phantom_vertices);
    header.mutable_phantom()->set_without_bones(source.phantom_without_bones);
    *header.mutable_options() = options;
    status = client.LoadMesh(std::move(header), {}, summary);
  } else {
    status = client.LoadMeshFiles(source.mesh_path, source.skeleton_path, options, summary,
                                  /*progress=*/{}, source.weights_path, source.bone_surfaces);
  }
  *loaded = status.ok();
  return status;
}

}  // namespace deform::cli
