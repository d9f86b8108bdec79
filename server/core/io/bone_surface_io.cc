#include "core/io/bone_surface_io.h"

#include <cctype>
#include <charconv>
#include <filesystem>
#include <vector>

#include "core/io/mesh_io.h"

namespace deform {

StatusOr<int> BoneFromName(const Skeleton& skeleton, std::string_view name) {
  int index = -1;
  const auto [end, error] = std::from_chars(name.data(), name.data() + name.size(), index);
  if (error == std::errc() && end == name.data() + name.size()) {
    if (index < 0 || index >= skeleton.num_bones()) {
      return Status::InvalidArgument("bone " + std::string(name) +
                                     " out of range (the skeleton has " +
                                     std::to_string(skeleton.num_bones()) + " bones)");
    }
    return index;
  }
  std::vector<int> starting;
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    const Bone& bone = skeleton.bone(k);
    const std::string& head = skeleton.joint(bone.head_joint).name;
    const std::string& tail = skeleton.joint(bone.tail_joint).name;
    if (name == head + "-" + tail) return k;
    if (name == head) starting.push_back(k);
  }
  if (starting.size() == 1) return starting.front();
  std::string known;
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    const Bone& bone = skeleton.bone(k);
    known += (k > 0 ? ", " : "") + std::to_string(k) + " " + skeleton.joint(bone.head_joint).name +
             "-" + skeleton.joint(bone.tail_joint).name;
  }
  if (starting.size() > 1) {
    return Status::InvalidArgument("joint '" + std::string(name) +
                                   "' starts several bones: name one as HEAD-TAIL or by index (" +
                                   known + ")");
  }
  return Status::InvalidArgument("no bone named '" + std::string(name) + "' (bones: " + known +
                                 ")");
}

StatusOr<BoneSurface> LoadBoneSurfaceSpec(std::string_view spec, const Skeleton& skeleton,
                                          const MeshLimits& limits) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string_view::npos || colon == 0 || colon + 1 == spec.size()) {
    return Status::InvalidArgument("bone surface '" + std::string(spec) +
                                   "' is not FILE:BONE (BONE a bone index, HEAD-TAIL or a joint)");
  }
  const std::string path(spec.substr(0, colon));
  BoneSurface surface;
  DEFORM_ASSIGN_OR_RETURN(surface.bone, BoneFromName(skeleton, spec.substr(colon + 1)));
  DEFORM_ASSIGN_OR_RETURN(surface.mesh, ReadMeshFile(path, limits));
  surface.name = std::filesystem::path(path).stem().string();
  DEFORM_RETURN_IF_ERROR(ValidateBoneSurfaces({surface}, skeleton, limits));
  return surface;
}

Status WritePosedBoneSurfaces(const std::vector<BoneSurface>& surfaces, const Skeleton& skeleton,
                              const std::vector<RigidTransform>& bones, const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir, error)) {
    return Status::FailedPrecondition("cannot create the directory '" + dir +
                                      "': " + (error ? error.message() : "not a directory"));
  }
  for (const BoneSurface& surface : surfaces) {
    const RigidTransform pose = BoneSurfaceTransform(surface, skeleton, bones);
    TriangleMesh posed = surface.mesh;
    for (int i = 0; i < posed.num_vertices(); ++i) {
      posed.vertices.row(i) = pose.Apply(posed.vertices.row(i).transpose()).transpose();
    }
    std::string name = surface.name.empty() ? "bone" : surface.name;
    for (char& c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
    }
    DEFORM_RETURN_IF_ERROR(WriteMeshFile(posed, dir + "/" + name + ".obj"));
  }
  return Status::Ok();
}

}  // namespace deform
