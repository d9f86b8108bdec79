// The --rotation-blend flag shared by the command-line clients: how the server blends bone
// rotations near a joint (deform.v1.RotationBlend). Header-only; the clients link CLI11.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>

#include "cli/enum_flag.h"
#include "deform/v1/deform.pb.h"

namespace deform::cli {

inline const std::map<std::string, deform::v1::RotationBlend>& RotationBlendNames() {
  static const std::map<std::string, deform::v1::RotationBlend> names = {
      {"quaternion", deform::v1::ROTATION_BLEND_QUATERNION},
      {"linear", deform::v1::ROTATION_BLEND_LINEAR}};
  return names;
}

inline std::string RotationBlendName(deform::v1::RotationBlend blend) {
  if (blend == deform::v1::ROTATION_BLEND_UNSPECIFIED) return "quaternion";  // the default
  return NameOf(RotationBlendNames(), blend, "unknown");
}

inline CLI::Option* AddRotationBlendFlag(CLI::App& app, deform::v1::RotationBlend* blend) {
  return AddEnumFlag(app, "--rotation-blend", blend, RotationBlendNames(),
                     "How the mesh loaded blends bone rotations near a joint: quaternion (the "
                     "method's default) or linear (linear between samples of the bones' "
                     "quaternion blend, four segments per weight: a precomputed response, no "
                     "solve per frame, a few tenths of a percent more volume loss at a bent "
                     "joint)",
                     "quaternion");
}

}  // namespace deform::cli
