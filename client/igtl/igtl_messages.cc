#include "igtl/igtl_messages.h"

#include <igtlPolyDataMessage.h>
#include <igtlTimeStamp.h>
#include <igtlTransformMessage.h>

#include <cstring>
#include <set>

namespace deform::igtl_bridge {
namespace {

void Stamp(MessageTime time, igtl::MessageBase* message) {
  igtl::TimeStamp::Pointer stamp = igtl::TimeStamp::New();
  if (time.seconds > 0) {
    stamp->SetTime(time.seconds);
  } else {
    stamp->GetTime();
  }
  message->SetTimeStamp(stamp);
}

std::string Packed(igtl::MessageBase* message) {
  message->Pack();
  return std::string(static_cast<const char*>(message->GetPackPointer()),
                     static_cast<std::size_t>(message->GetPackSize()));
}

igtl::PolyDataPointArray::Pointer MappedPoints(const std::string& positions,
                                               const RasFrame& frame) {
  const std::size_t vertices = positions.size() / (3 * sizeof(float));
  igtl::PolyDataPointArray::Pointer points = igtl::PolyDataPointArray::New();
  points->SetNumberOfPoints(static_cast<int>(vertices));
  for (std::size_t v = 0; v < vertices; ++v) {
    float model[3];
    std::memcpy(model, positions.data() + 3 * sizeof(float) * v, sizeof(model));
    float ras[3];
    frame.MapPoint(model, ras);
    points->SetPoint(static_cast<unsigned int>(v), ras);
  }
  return points;
}

}  // namespace

std::string PackTopology(const std::string& positions, const std::string& triangles,
                         const RasFrame& frame, MessageTime time) {
  igtl::PolyDataMessage::Pointer message = igtl::PolyDataMessage::New();
  message->SetDeviceName(kTopologyDevice);
  Stamp(time, message.GetPointer());
  message->SetPoints(MappedPoints(positions, frame));
  igtl::PolyDataCellArray::Pointer polygons = igtl::PolyDataCellArray::New();
  const std::size_t count = triangles.size() / (3 * sizeof(std::uint32_t));
  for (std::size_t t = 0; t < count; ++t) {
    igtlUint32 cell[3];
    std::memcpy(cell, triangles.data() + 3 * sizeof(std::uint32_t) * t, sizeof(cell));
    if (frame.mirrors()) std::swap(cell[1], cell[2]);
    polygons->AddCell(3, cell);
  }
  message->SetPolygons(polygons);
  return Packed(message.GetPointer());
}

std::string PackPoints(const std::string& positions, const RasFrame& frame, MessageTime time) {
  igtl::PolyDataMessage::Pointer message = igtl::PolyDataMessage::New();
  message->SetDeviceName(kPointsDevice);
  Stamp(time, message.GetPointer());
  message->SetPoints(MappedPoints(positions, frame));
  return Packed(message.GetPointer());
}

std::string PackTransform(const std::string& device, const std::array<std::array<float, 4>, 4>& m,
                          MessageTime time) {
  igtl::TransformMessage::Pointer message = igtl::TransformMessage::New();
  message->SetDeviceName(device.c_str());
  Stamp(time, message.GetPointer());
  igtl::Matrix4x4 matrix;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      matrix[r][c] = m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  }
  message->SetMatrix(matrix);
  return Packed(message.GetPointer());
}

std::vector<std::string> BoneDeviceNames(const deform::v1::MeshSummary& summary) {
  std::vector<std::string> names;
  std::set<std::string> taken;
  for (int b = 0; b < summary.bones_size(); ++b) {
    const deform::v1::BoneInfo& bone = summary.bones(b);
    std::string name;
    if (static_cast<int>(bone.head_joint()) < summary.joints_size() &&
        static_cast<int>(bone.tail_joint()) < summary.joints_size()) {
      name = summary.joints(static_cast<int>(bone.head_joint())).name() + "-" +
             summary.joints(static_cast<int>(bone.tail_joint())).name();
    }
    if (name.empty() || name.size() > kMaxDeviceNameBytes || taken.count(name) > 0) {
      name = "Bone" + std::to_string(b);
    }
    taken.insert(name);
    names.push_back(name);
  }
  return names;
}

}  // namespace deform::igtl_bridge
