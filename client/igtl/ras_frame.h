// The frame the bridge sends in: OpenIGTLink receivers such as 3D Slicer expect RAS (x right,
// y anterior, z superior) in millimetres, and a mesh's model frame is whatever its file used. The
// bridge maps model coordinates by a scale and a signed permutation of the axes, the same for
// every point and every bone transform it sends.
#pragma once

#include <array>
#include <string>

namespace deform::igtl_bridge {

class RasFrame {
 public:
  // The identity: model units sent as they are.
  RasFrame() = default;

  // `axes`: three comma-separated signed model axes naming what becomes R, A and S, each of x, y,
  // z once ("x,y,z" is the identity; "-x,z,y" turns a Y-up model facing +Z, as glTF and the
  // shared leg are, into RAS). `mm_per_unit`: millimetres per model unit, finite and > 0 (100
  // for decimetres). False, with `error` set, for anything else.
  static bool Parse(const std::string& axes, double mm_per_unit, RasFrame* frame,
                    std::string* error);

  // out = scale * A * in: a model point in RAS millimetres.
  void MapPoint(const float in[3], float out[3]) const;
  // The rigid motion posed = R rest + t (model frame, row-major R) as the 4x4 row-major matrix
  // of the same motion in RAS millimetres: [A R A^T | scale A t].
  std::array<std::array<float, 4>, 4> MapMotion(const float rotation[9],
                                                const float translation[3]) const;
  // True when A is a reflection (determinant -1): triangles then need their winding reversed to
  // keep their normals pointing outwards.
  bool mirrors() const { return mirrors_; }
  double mm_per_unit() const { return scale_; }

 private:
  // RAS axis r takes sign_[r] * model axis source_[r].
  std::array<int, 3> source_{0, 1, 2};
  std::array<int, 3> sign_{1, 1, 1};
  double scale_ = 1.0;
  bool mirrors_ = false;
};

}  // namespace deform::igtl_bridge
