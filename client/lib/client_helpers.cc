// The client-side helpers declared at the end of deform_client.h.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "deform_client.h"

namespace deform::client {
namespace {

std::string_view Trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

}  // namespace

bool ParsePoseAngles(const std::string& spec, deform::v1::PoseUpdate* pose, std::string* error) {
  const std::string_view all = Trim(spec);
  if (all.empty() || all == "rest") return true;
  std::size_t start = 0;
  while (start <= all.size()) {
    const std::size_t comma = std::min(all.find(',', start), all.size());
    const std::string_view term = Trim(all.substr(start, comma - start));
    const std::size_t first = term.find(':');
    const std::size_t second = first == std::string_view::npos ? first : term.find(':', first + 1);
    if (second == std::string_view::npos || term.find(':', second + 1) != std::string_view::npos) {
      if (error != nullptr) {
        *error =
            "INVALID_ARGUMENT: pose term '" + std::string(term) + "' is not JOINT:AXIS:DEGREES";
      }
      return false;
    }
    const std::string joint(Trim(term.substr(0, first)));
    const std::string axis(Trim(term.substr(first + 1, second - first - 1)));
    const std::string degrees_text(Trim(term.substr(second + 1)));
    char* end = nullptr;
    const double degrees = std::strtod(degrees_text.c_str(), &end);
    if (joint.empty() || axis.empty() || degrees_text.empty() ||
        end != degrees_text.c_str() + degrees_text.size()) {
      if (error != nullptr) {
        *error =
            "INVALID_ARGUMENT: pose term '" + std::string(term) + "' is not JOINT:AXIS:DEGREES";
      }
      return false;
    }
    deform::v1::JointAngle* angle = pose->add_angles();
    angle->set_joint(joint);
    angle->set_axis(axis);
    angle->set_degrees(degrees);
    start = comma + 1;
  }
  return true;
}

std::vector<float> DecodePositions(const std::string& bytes) {
  std::vector<float> values(bytes.size() / 4);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::uint32_t bits = static_cast<std::uint32_t>(data[4 * k]) |
                               static_cast<std::uint32_t>(data[4 * k + 1]) << 8 |
                               static_cast<std::uint32_t>(data[4 * k + 2]) << 16 |
                               static_cast<std::uint32_t>(data[4 * k + 3]) << 24;
    std::memcpy(&values[k], &bits, sizeof(float));
  }
  return values;
}

std::int64_t MonotonicNanos() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

deform::v1::MeshFormat MeshFormatFromPath(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  if (dot == std::string::npos) return deform::v1::MESH_FORMAT_UNSPECIFIED;
  std::string extension = path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == "obj") return deform::v1::MESH_FORMAT_OBJ;
  if (extension == "ply") return deform::v1::MESH_FORMAT_PLY;
  if (extension == "stl") return deform::v1::MESH_FORMAT_STL;
  if (extension == "off") return deform::v1::MESH_FORMAT_OFF;
  return deform::v1::MESH_FORMAT_UNSPECIFIED;
}

}  // namespace deform::client
