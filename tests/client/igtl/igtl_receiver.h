// A test's OpenIGTLink receiver, built on the OpenIGTLink library's own receiving code
// (igtl::ClientSocket, igtl::MessageHeader, the messages' Unpack with the CRC checked), the way
// 3D Slicer's OpenIGTLinkIF reads a server.
#pragma once

#include <igtlClientSocket.h>
#include <igtlMessageHeader.h>
#include <igtlPolyDataMessage.h>
#include <igtlStringMessage.h>
#include <igtlTransformMessage.h>

#include <array>
#include <string>
#include <vector>

namespace deform::test_support {

struct ReceivedMessage {
  std::string type;    // the header's type: "POLYDATA", "TRANSFORM", ...
  std::string device;  // the header's device name
  int bytes = 0;       // header and body as they travelled
  // POLYDATA: x, y, z per point; the cell lists' sizes.
  std::vector<float> points;
  std::uint32_t polygons = 0;
  std::uint32_t vertices = 0;
  std::uint32_t lines = 0;
  std::uint32_t strips = 0;
  // TRANSFORM: row-major 4 x 4.
  std::array<std::array<float, 4>, 4> matrix{};
};

class IgtlReceiver {
 public:
  // Connects to 127.0.0.1:`port`; false when it cannot. Reads give up after `timeout_ms`.
  bool Connect(int port, int timeout_ms = 10000) {
    socket_ = igtl::ClientSocket::New();
    if (socket_->ConnectToServer("127.0.0.1", port) != 0) return false;
    socket_->SetReceiveTimeout(timeout_ms);
    return true;
  }
  void Close() {
    if (socket_.IsNotNull()) socket_->CloseSocket();
  }

  // Reads the next message; false (with `error`) on timeout, a closed connection, or a message
  // whose body does not unpack (CRC checked).
  bool Read(ReceivedMessage* out, std::string* error) {
    igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
    header->InitPack();
    if (!ReceiveFully(header->GetPackPointer(), header->GetPackSize())) {
      *error = "no header (timeout or closed)";
      return false;
    }
    if ((header->Unpack() & igtl::MessageHeader::UNPACK_HEADER) == 0) {
      *error = "a header that does not unpack";
      return false;
    }
    out->type = header->GetDeviceType();
    out->device = header->GetDeviceName();
    out->bytes = header->GetPackSize() + static_cast<int>(header->GetBodySizeToRead());
    if (out->type == "POLYDATA") {
      igtl::PolyDataMessage::Pointer message = igtl::PolyDataMessage::New();
      if (!ReadBody(header, message.GetPointer(), error)) return false;
      igtl::PolyDataPointArray* points = message->GetPoints();
      const int count = points != nullptr ? points->GetNumberOfPoints() : 0;
      out->points.resize(3 * static_cast<std::size_t>(count));
      for (int i = 0; i < count; ++i)
        points->GetPoint(static_cast<unsigned int>(i),
                         &out->points[3 * static_cast<std::size_t>(i)]);
      out->polygons = CellCount(message->GetPolygons());
      out->vertices = CellCount(message->GetVertices());
      out->lines = CellCount(message->GetLines());
      out->strips = CellCount(message->GetTriangleStrips());
      return true;
    }
    if (out->type == "TRANSFORM") {
      igtl::TransformMessage::Pointer message = igtl::TransformMessage::New();
      if (!ReadBody(header, message.GetPointer(), error)) return false;
      igtl::Matrix4x4 matrix;
      message->GetMatrix(matrix);
      for (std::size_t r = 0; r < 4; ++r) {
        for (std::size_t c = 0; c < 4; ++c) out->matrix[r][c] = matrix[r][c];
      }
      return true;
    }
    igtl::MessageBase::Pointer other = igtl::MessageBase::New();
    other->SetMessageHeader(header);
    other->AllocatePack();
    if (!ReceiveFully(other->GetPackBodyPointer(), other->GetPackBodySize())) {
      *error = "a body cut short";
      return false;
    }
    return true;
  }

  // Sends a STRING message (device "Pose") holding `text`.
  bool SendString(const std::string& text) {
    igtl::StringMessage::Pointer message = igtl::StringMessage::New();
    message->SetDeviceName("Pose");
    message->SetString(text.c_str());
    message->Pack();
    return socket_->Send(message->GetPackPointer(), message->GetPackSize()) == 1;
  }

  // Sends raw bytes (a malformed message).
  bool SendRaw(const std::string& bytes) {
    return socket_->Send(bytes.data(), static_cast<int>(bytes.size())) == 1;
  }

 private:
  // Socket::Receive reads what has arrived once a timeout is set (readFully is then ignored):
  // it is called until `length` bytes have come. False on timeout (-1) or error (0).
  bool ReceiveFully(void* data, int length) {
    auto* bytes = static_cast<char*>(data);
    while (length > 0) {
      const int got = socket_->Receive(bytes, length);
      if (got <= 0) return false;
      bytes += got;
      length -= got;
    }
    return true;
  }

  static std::uint32_t CellCount(igtl::PolyDataCellArray* cells) {
    return cells != nullptr ? cells->GetNumberOfCells() : 0;
  }

  bool ReadBody(const igtl::MessageHeader::Pointer& header, igtl::MessageBase* message,
                std::string* error) {
    message->SetMessageHeader(header);
    message->AllocatePack();
    if (!ReceiveFully(message->GetPackBodyPointer(), message->GetPackBodySize())) {
      *error = "a body cut short";
      return false;
    }
    if ((message->Unpack(/*crccheck=*/1) & igtl::MessageHeader::UNPACK_BODY) == 0) {
      *error = "a " + std::string(header->GetDeviceType()) + " body that does not unpack";
      return false;
    }
    return true;
  }

  igtl::ClientSocket::Pointer socket_;
};

}  // namespace deform::test_support
