#include "service/load/load_request.h"

#include <algorithm>
#include <climits>
#include <iterator>
#include <utility>

#include "core/geometry/bone_surface.h"
#include "core/geometry/skeleton.h"
#include "core/io/bone_surface_io.h"
#include "core/io/declared_mesh_size.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "service/base/log_text.h"
#include "service/base/request_limits.h"
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
                                     std::to_string(static_cast<int>(format)) + ")")
          .WithSubject("upload.skeleton_format");
  }
}

Status ParseUpload(const v1::UploadSource& upload, std::string* mesh_bytes,
                   const ServiceLimits& service_limits, LoadJob* job) {
  MeshLimits limits;
  limits.max_vertices = service_limits.max_vertices;
  if (upload.format() == v1::MESH_FORMAT_GLTF) {
    auto rig = ReadGltf(*mesh_bytes, limits);
    std::string().swap(*mesh_bytes);
    if (!rig.ok()) return InField(rig.status().WithContext("glTF"), "chunk");
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
    job->file_metadata.warnings = std::move(rig->warnings);
    if (!upload.skip_gltf_bone_nodes()) job->bone_surfaces = std::move(rig->bone_surfaces);
    return Status::Ok();
  }
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, CoreMeshFormat(upload.format()));
  auto mesh = ReadMesh(*mesh_bytes, format, limits);
  if (!mesh.ok()) return InField(mesh.status().WithContext("mesh"), "chunk");
  job->mesh = std::move(*mesh);
  std::string().swap(*mesh_bytes);  // the bytes are no longer needed
  auto skeleton = ParseSkeleton(upload.skeleton_format(), upload.skeleton());
  if (!skeleton.ok()) return InField(skeleton.status().WithContext("skeleton"), "upload.skeleton");
  job->skeleton = std::move(*skeleton);
  if (!upload.weights().empty()) {
    DEFORM_ASSIGN_OR_RETURN(const SkinWeightsFormat format,
                            CoreWeightsFormat(upload.weights_format()));
    auto weights = ReadSkinWeights(upload.weights(), format, limits);
    if (!weights.ok()) return InField(weights.status().WithContext("weights"), "upload.weights");
    WidenSkinWeights(format, job->mesh.num_vertices(), job->skeleton.num_bones(), &*weights);
    job->weights = std::move(*weights);
  }
  return Status::Ok();
}

// The bone `name` means (BoneFromName), its error prefixed by `field` and naming the request
// field `path`; a name that is not printable ASCII is repeated only escaped and cut.
StatusOr<int> BoneOf(const Skeleton& skeleton, const std::string& name, const std::string& field,
                     const std::string& path) {
  StatusOr<int> bone = BoneFromName(skeleton, name);
  if (bone.ok()) return bone;
  if (EscapeForLog(name) != name) {
    return Status::InvalidArgument(field + ": no bone named " + EchoForClient(name))
        .WithSubject(path);
  }
  return Status::InvalidArgument(field + ": " + bone.status().message()).WithSubject(path);
}

// An upload's bone surfaces: each mesh parsed (its reader validates it), its bones resolved, all
// of them checked against the skeleton. Names default to "bone_surfaces[i]" and are kept escaped
// (printable ASCII as given), as summaries and errors repeat them.
StatusOr<std::vector<BoneSurface>> ParseBoneSurfaces(const v1::UploadSource& upload,
                                                     const Skeleton& skeleton,
                                                     const MeshLimits& limits) {
  std::vector<BoneSurface> surfaces;
  for (int i = 0; i < upload.bone_surfaces_size(); ++i) {
    const v1::BoneSurfaceUpload& proto = upload.bone_surfaces(i);
    BoneSurface surface;
    surface.name = proto.name().empty() ? "bone_surfaces[" + std::to_string(i) + "]"
                                        : EscapeForLog(proto.name(), kMaxMeshNameBytes);
    const std::string field = "bone surface '" + surface.name + "'";
    const std::string path = "upload.bone_surfaces[" + std::to_string(i) + "]";
    DEFORM_ASSIGN_OR_RETURN(surface.bone,
                            BoneOf(skeleton, proto.bone(), field + " bone", path + ".bone"));
    if (!proto.blend_bone().empty()) {
      DEFORM_ASSIGN_OR_RETURN(
          surface.blend_bone,
          BoneOf(skeleton, proto.blend_bone(), field + " blend_bone", path + ".blend_bone"));
      surface.blend = proto.blend();
    } else if (proto.blend() != 0) {
      return Status::InvalidArgument(field + ": blend is given without a blend_bone")
          .WithSubject(path + ".blend");
    }
    DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, CoreMeshFormat(proto.format()));
    auto mesh = ReadMesh(proto.mesh(), format, limits);
    if (!mesh.ok()) return InField(mesh.status().WithContext(field + " mesh"), path + ".mesh");
    surface.mesh = std::move(*mesh);
    surfaces.push_back(std::move(surface));
  }
  DEFORM_RETURN_IF_ERROR(ValidateBoneSurfaces(surfaces, skeleton, limits));
  return surfaces;
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
    if (!header.phantom().without_bones()) job.bone_surfaces = std::move(phantom.bones);
    if (job.name.empty()) job.name = "phantom:" + std::to_string(vertices);
  } else {
    DEFORM_RETURN_IF_ERROR(ParseUpload(header.upload(), mesh_bytes, limits, &job));
    if (job.name.empty()) job.name = "upload";
    MeshLimits mesh_limits;
    mesh_limits.max_vertices = limits.max_vertices;
    DEFORM_ASSIGN_OR_RETURN(std::vector<BoneSurface> uploaded,
                            ParseBoneSurfaces(header.upload(), job.skeleton, mesh_limits));
    job.bone_surfaces.insert(job.bone_surfaces.end(), std::make_move_iterator(uploaded.begin()),
                             std::make_move_iterator(uploaded.end()));
    DEFORM_RETURN_IF_ERROR(ValidateBoneSurfaces(job.bone_surfaces, job.skeleton, mesh_limits));
  }
  auto options = ModelOptionsFromProto(header.options(), job.skeleton);
  if (!options.ok()) return InField(options.status().WithContext("options"), "options");
  job.options = std::move(*options);
  auto constraints = ConstraintOptionsFromProto(header.options().constraints());
  if (!constraints.ok()) {
    return InField(constraints.status().WithContext("options.constraints"), "options.constraints");
  }
  job.constraints = *constraints;
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
                                     std::to_string(limits.max_vertices) + " (--max-vertices)")
        .WithLimit("server", "--max-vertices");
  }
  const auto clamp = [](std::size_t count) {
    return static_cast<int>(std::min<std::size_t>(count, INT_MAX));
  };
  return mesh_bytes.size() + DeformationModel::EstimateBytesBeforeBuild(clamp(declared->vertices),
                                                                        clamp(declared->faces));
}

}  // namespace deform::service
