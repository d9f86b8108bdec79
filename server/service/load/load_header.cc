#include "service/load/load_header.h"

#include <string>

#include "core/io/phantom.h"
#include "service/base/request_limits.h"

namespace deform::service {
namespace {

// The header checks of an upload's skeleton and weights: a glTF rig carries both, so neither may
// be given beside it; other formats need a skeleton, and weights only with their format.
Status CheckUploadParts(const v1::UploadSource& upload) {
  if (upload.format() == v1::MESH_FORMAT_GLTF) {
    if (!upload.skeleton().empty() || !upload.weights().empty()) {
      return Status::InvalidArgument(
                 "a glTF upload carries its own skeleton and weights: upload.skeleton and "
                 "upload.weights must be empty")
          .WithSubject(upload.skeleton().empty() ? "upload.weights" : "upload.skeleton");
    }
    return Status::Ok();
  }
  DEFORM_RETURN_IF_ERROR(CoreMeshFormat(upload.format()).status());
  if (upload.skeleton().empty()) {
    return Status::InvalidArgument("upload.skeleton is empty").WithSubject("upload.skeleton");
  }
  if (upload.skeleton_format() != v1::SKELETON_FORMAT_TGF &&
      upload.skeleton_format() != v1::SKELETON_FORMAT_JSON) {
    return Status::InvalidArgument("upload.skeleton_format is unspecified or unknown")
        .WithSubject("upload.skeleton_format");
  }
  if (!upload.weights().empty()) {
    DEFORM_RETURN_IF_ERROR(CoreWeightsFormat(upload.weights_format()).status());
  }
  return Status::Ok();
}

// The header checks of an upload's bone surfaces: each names its mesh's format and its bone, and
// all their bytes together stay within the limit.
Status CheckBoneSurfaces(const v1::LoadMeshHeader& header, const ServiceLimits& limits) {
  const auto& bones = header.upload().bone_surfaces();
  for (int i = 0; i < bones.size(); ++i) {
    const std::string field = "upload.bone_surfaces[" + std::to_string(i) + "]";
    if (bones[i].mesh().empty()) {
      return Status::InvalidArgument(field + ".mesh is empty").WithSubject(field + ".mesh");
    }
    if (bones[i].bone().empty()) {
      return Status::InvalidArgument(field + ".bone is empty: name the bone that carries it")
          .WithSubject(field + ".bone");
    }
    if (!CoreMeshFormat(bones[i].format()).ok()) {
      return Status::InvalidArgument(field + ".format must be OBJ, PLY, STL or OFF, got " +
                                     std::to_string(static_cast<int>(bones[i].format())))
          .WithSubject(field + ".format");
    }
  }
  const std::uint64_t bytes = BoneSurfaceBytes(header);
  if (bytes > limits.max_bone_surface_bytes) {
    return Status::ResourceExhausted("bone surfaces of " + std::to_string(bytes) + " bytes (" +
                                     std::to_string(bones.size()) + " files) exceed the limit of " +
                                     std::to_string(limits.max_bone_surface_bytes) +
                                     " bytes (--max-bone-surface-mb)")
        .WithLimit("server", "--max-bone-surface-mb");
  }
  return Status::Ok();
}

}  // namespace

std::uint64_t BoneSurfaceBytes(const v1::LoadMeshHeader& header) {
  std::uint64_t bytes = 0;
  for (const v1::BoneSurfaceUpload& bone : header.upload().bone_surfaces()) {
    bytes += bone.mesh().size();
  }
  return bytes;
}

StatusOr<MeshFormat> CoreMeshFormat(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_OBJ:
      return MeshFormat::kObj;
    case v1::MESH_FORMAT_PLY:
      return MeshFormat::kPly;
    case v1::MESH_FORMAT_STL:
      return MeshFormat::kStl;
    case v1::MESH_FORMAT_OFF:
      return MeshFormat::kOff;
    default:
      return Status::InvalidArgument("upload.format is unspecified or unknown (" +
                                     std::to_string(static_cast<int>(format)) + ")")
          .WithSubject("upload.format");
  }
}

StatusOr<SkinWeightsFormat> CoreWeightsFormat(v1::SkinWeightsFormat format) {
  switch (format) {
    case v1::SKIN_WEIGHTS_FORMAT_DMAT:
      return SkinWeightsFormat::kDmat;
    case v1::SKIN_WEIGHTS_FORMAT_CSV:
      return SkinWeightsFormat::kCsv;
    default:
      return Status::InvalidArgument("upload.weights_format is unspecified or unknown (" +
                                     std::to_string(static_cast<int>(format)) + ")")
          .WithSubject("upload.weights_format");
  }
}

Status CheckLoadHeader(const v1::LoadMeshHeader& header, const ServiceLimits& limits) {
  DEFORM_RETURN_IF_ERROR(CheckLoadHeaderStrings(header));
  switch (header.source_case()) {
    case v1::LoadMeshHeader::kPhantom: {
      const int vertices = header.phantom().vertices();
      if (vertices < 0) {
        return Status::InvalidArgument("phantom.vertices must not be negative, got " +
                                       std::to_string(vertices))
            .WithSubject("phantom.vertices");
      }
      const int effective = vertices == 0 ? kDefaultPhantomVertices : vertices;
      if (static_cast<std::size_t>(effective) > limits.max_vertices) {
        return Status::ResourceExhausted("a phantom of " + std::to_string(effective) +
                                         " vertices exceeds the limit of " +
                                         std::to_string(limits.max_vertices) + " vertices per mesh")
            .WithLimit("server", "--max-vertices");
      }
      return Status::Ok();
    }
    case v1::LoadMeshHeader::kUpload: {
      const v1::UploadSource& upload = header.upload();
      DEFORM_RETURN_IF_ERROR(CheckUploadParts(upload));
      DEFORM_RETURN_IF_ERROR(CheckBoneSurfaces(header, limits));
      if (upload.mesh_size_bytes() == 0) {
        return Status::InvalidArgument(
                   "upload.mesh_size_bytes is 0: the mesh file size is required")
            .WithSubject("upload.mesh_size_bytes");
      }
      return CheckUploadSize(upload.mesh_size_bytes(), upload.skeleton().size(),
                             upload.weights().size(), limits.max_upload_bytes);
    }
    case v1::LoadMeshHeader::SOURCE_NOT_SET:
      break;
  }
  return Status::InvalidArgument("the header names no source (phantom or upload)");
}

}  // namespace deform::service
