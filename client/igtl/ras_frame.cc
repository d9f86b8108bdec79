#include "igtl/ras_frame.h"

#include <cmath>
#include <vector>

#include "core/base/text.h"

namespace deform::igtl_bridge {

bool RasFrame::Parse(const std::string& axes, double mm_per_unit, RasFrame* frame,
                     std::string* error) {
  if (!std::isfinite(mm_per_unit) || mm_per_unit <= 0) {
    *error = "millimetres per model unit must be finite and > 0";
    return false;
  }
  const std::vector<std::string_view> parts = Split(axes, ',');
  RasFrame parsed;
  std::array<bool, 3> used{false, false, false};
  bool valid = parts.size() == 3;
  for (std::size_t r = 0; valid && r < 3; ++r) {
    std::string_view part = Trim(parts[r]);
    int sign = 1;
    if (!part.empty() && (part[0] == '-' || part[0] == '+')) {
      sign = part[0] == '-' ? -1 : 1;
      part.remove_prefix(1);
    }
    const int axis = part == "x" ? 0 : part == "y" ? 1 : part == "z" ? 2 : -1;
    valid = axis >= 0 && !used[static_cast<std::size_t>(axis)];
    if (!valid) break;
    used[static_cast<std::size_t>(axis)] = true;
    parsed.source_[r] = axis;
    parsed.sign_[r] = sign;
  }
  if (!valid) {
    *error = "axes must name each of x, y, z once, signed, comma-separated (e.g. -x,z,y), not '" +
             axes + "'";
    return false;
  }
  // The permutation's parity times the signs' product is the determinant.
  const std::array<int, 3>& s = parsed.source_;
  const int inversions = (s[0] > s[1]) + (s[0] > s[2]) + (s[1] > s[2]);
  const int determinant =
      (inversions % 2 == 0 ? 1 : -1) * parsed.sign_[0] * parsed.sign_[1] * parsed.sign_[2];
  parsed.mirrors_ = determinant < 0;
  parsed.scale_ = mm_per_unit;
  *frame = parsed;
  return true;
}

void RasFrame::MapPoint(const float in[3], float out[3]) const {
  for (int r = 0; r < 3; ++r) {
    out[r] = static_cast<float>(scale_ * sign_[r] * in[source_[r]]);
  }
}

std::array<std::array<float, 4>, 4> RasFrame::MapMotion(const float rotation[9],
                                                        const float translation[3]) const {
  std::array<std::array<float, 4>, 4> m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      // (A R A^T)[r][c] = sign_r sign_c R[source_r][source_c].
      m[r][c] = static_cast<float>(sign_[r] * sign_[c]) * rotation[3 * source_[r] + source_[c]];
    }
    m[r][3] = static_cast<float>(scale_ * sign_[r] * translation[source_[r]]);
  }
  m[3] = {0, 0, 0, 1};
  return m;
}

}  // namespace deform::igtl_bridge
