#include "service/load/load_request.h"

#include <algorithm>
#include <climits>
#include <utility>

#include "core/geometry/skeleton.h"
#include "core/io/declared_mesh_size.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "service/load/load_header.h"
#include "service/messages/proto_conversion.h"

namespace deform::service {
namespace {

StatusOr<Skeleton> ParseSkeleton(v1::SkeletonFormat format, const std::string& bytes) {
  switch (format) {
    case v1::SKELETON_FORMAT_TGF:
      return ParseTgf(bytes);
    case v1::SKELETON_FORMAT_JSON:
      return ParseSkeletonJson(bytes);
    default:
      return Status::InvalidArgument("upload.skeleton_format is unspecified or unknown (" +
                                     std::to_string(static_cast<int>(format)) + ")");
  }
}

Status ParseUpload(const v1::UploadSource& upload, std::string* mesh_bytes,
                   const ServiceLimits& service_limits, LoadJob* job) {
  MeshLimits limits;
  limits.max_vertices = service_limits.max_vertices;
  if (upload.format() == v1::MESH_FORMAT_GLTF) {
    auto rig = ReadGltf(*mesh_bytes, limits);
    std::string().swap(*mesh_bytes);
    if (!rig.ok()) return rig.status().WithContext("glTF");
    job->mesh = std::move(rig->mesh);
    job->skeleton = std::move(rig->skeleton);
    job->weights = std::move(rig->weights);
    // Frames, rest positions and vertex indices go through this map: every entry must name a
    // vertex of the mesh (ReadGltf's contract, checked here where it starts to matter).
    const int vertices = job->mesh.num_vertices();
    for (const int m : rig->file_vertex_to_mesh) {
      if (m < 0 || m >= vertices) {
        return Status::Internal("glTF: a file vertex maps to vertex " + std::to_string(m) +
                                " of a " + std::to_string(vertices) + "-vertex mesh");
      }
    }
    job->file_metadata.file_vertex_to_mesh = std::move(rig->file_vertex_to_mesh);
    job->file_metadata.unused_file_vertices = std::move(rig->unused_file_vertices);
    job->file_metadata.units = std::move(rig->units);
    job->file_metadata.up_axis = std::move(rig->up_axis);
    return Status::Ok();
  }
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, CoreMeshFormat(upload.format()));
  auto mesh = ReadMesh(*mesh_bytes, format, limits);
  if (!mesh.ok()) return mesh.status().WithContext("mesh");
  job->mesh = std::move(*mesh);
  std::string().swap(*mesh_bytes);  // the bytes are no longer needed
  auto skeleton = ParseSkeleton(upload.skeleton_format(), upload.skeleton());
  if (!skeleton.ok()) return skeleton.status().WithContext("skeleton");
  job->skeleton = std::move(*skeleton);
  if (!upload.weights().empty()) {
    DEFORM_ASSIGN_OR_RETURN(const SkinWeightsFormat format,
                            CoreWeightsFormat(upload.weights_format()));
    auto weights = ReadSkinWeights(upload.weights(), format, limits);
    if (!weights.ok()) return weights.status().WithContext("weights");
    WidenSkinWeights(format, job->mesh.num_vertices(), job->skeleton.num_bones(), &*weights);
    job->weights = std::move(*weights);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<LoadJob> LoadJobFromRequest(const v1::LoadMeshHeader& header, std::string* mesh_bytes,
                                     const ServiceLimits& limits) {
  LoadJob job;
  job.name = header.name();
  if (header.has_phantom()) {
    const int vertices =
        header.phantom().vertices() == 0 ? kDefaultPhantomVertices : header.phantom().vertices();
    DEFORM_ASSIGN_OR_RETURN(KneePhantom phantom, MakeKneePhantom(vertices));
    job.mesh = std::move(phantom.mesh);
    job.skeleton = std::move(phantom.skeleton);
    if (job.name.empty()) job.name = "phantom:" + std::to_string(vertices);
  } else {
    DEFORM_RETURN_IF_ERROR(ParseUpload(header.upload(), mesh_bytes, limits, &job));
    if (job.name.empty()) job.name = "upload";
  }
  auto options = ModelOptionsFromProto(header.options(), job.skeleton);
  if (!options.ok()) return options.status().WithContext("options");
  job.options = std::move(*options);
  return job;
}

StatusOr<std::size_t> DeclaredLoadBytes(const v1::LoadMeshHeader& header,
                                        const std::string& mesh_bytes, const ServiceLimits& limits,
                                        std::string* subject) {
  if (!header.has_upload() || header.upload().format() == v1::MESH_FORMAT_GLTF) return 0;
  const StatusOr<MeshFormat> format = CoreMeshFormat(header.upload().format());
  if (!format.ok()) return 0;  // the parse names it
  const std::optional<DeclaredMeshSize> declared = ReadDeclaredMeshSize(mesh_bytes, *format);
  if (!declared.has_value()) return 0;
  *subject = "a mesh of " + std::to_string(declared->vertices) + " vertices and " +
             std::to_string(declared->faces) + " faces (as its " + MeshFormatName(*format) +
             " data declares)";
  if (declared->vertices > limits.max_vertices) {
    return Status::ResourceExhausted("the " + std::string(MeshFormatName(*format)) +
                                     " data declares " + std::to_string(declared->vertices) +
                                     " vertices, more than the limit of " +
                                     std::to_string(limits.max_vertices) + " (--max-vertices)");
  }
  const auto clamp = [](std::size_t count) {
    return static_cast<int>(std::min<std::size_t>(count, INT_MAX));
  };
  return mesh_bytes.size() + DeformationModel::EstimateBytesBeforeBuild(clamp(declared->vertices),
                                                                        clamp(declared->faces));
}

}  // namespace deform::service
