#include "core/geometry/enclosed_volume.h"

#include "core/geometry/volume_closure.h"

namespace deform {

double EnclosedVolume(const Positions& positions, const Triangles& triangles) {
  return VolumeClosure(triangles, static_cast<int>(positions.rows())).Volume(positions.data());
}

}  // namespace deform
