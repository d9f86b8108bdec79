// Bone surfaces from files and command lines: a triangle mesh file (any format ReadMesh reads)
// attached to a skeleton bone named by index or by joint.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/skeleton.h"

namespace deform {

// The bone `name` means: a bone index ("3"); "HEAD-TAIL", the bone between those joints; or a
// joint's name, the bone whose head it is (a glTF joint is the bone that starts there), which must
// be unique. INVALID_ARGUMENT naming the candidates otherwise.
StatusOr<int> BoneFromName(const Skeleton& skeleton, std::string_view name);

// "FILE:BONE" (the first ':' splits, so BONE may hold colons, as Mixamo's joint names do): the
// mesh in FILE attached to BONE (BoneFromName), named after the file. Validated with
// ValidateBoneSurfaces against `skeleton`.
StatusOr<BoneSurface> LoadBoneSurfaceSpec(std::string_view spec, const Skeleton& skeleton,
                                          const MeshLimits& limits = {});

// Writes `surfaces` posed by `bones` (ForwardKinematics of the frame) as DIR/NAME.obj, one file per
// surface (NAME with anything but letters, digits, '-', '_' and '.' replaced by '_'), creating DIR
// (and its parents) when missing. FAILED_PRECONDITION naming DIR when it cannot be created.
Status WritePosedBoneSurfaces(const std::vector<BoneSurface>& surfaces, const Skeleton& skeleton,
                              const std::vector<RigidTransform>& bones, const std::string& dir);

}  // namespace deform
