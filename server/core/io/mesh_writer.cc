// Writing meshes. Done directly rather than through OpenMesh's halfedge writers: simple,
// lossless, and independent of halfedge topology, so any triangle soup can be written.
#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <type_traits>

#include "internal/mesh_io_internal.h"

namespace deform::mesh_io_internal {
namespace {

bool HostIsLittleEndian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

template <typename T>
void AppendLittleEndian(std::string* out, T value) {
  static_assert(std::is_arithmetic_v<T>, "raw numbers only");
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (!HostIsLittleEndian()) std::reverse(bytes, bytes + sizeof(T));
  out->append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

// What writing needs: indices in range (else out-of-bounds reads) and finite coordinates (else
// a file that cannot be read back). Anything else (degenerate, non-manifold) is written as is.
Status CheckWritable(const TriangleMesh& mesh) {
  if (!mesh.vertices.allFinite()) {
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
      if (!mesh.vertices.row(v).allFinite()) {
        return Status::InvalidArgument("vertex " + std::to_string(v) +
                                       " has a non-finite coordinate");
      }
    }
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.triangles(t, c);
      if (v < 0 || v >= mesh.vertices.rows()) {
        return Status::InvalidArgument("triangle " + std::to_string(t) + " references vertex " +
                                       std::to_string(v) + " but the mesh has " +
                                       std::to_string(mesh.vertices.rows()) + " vertices");
      }
    }
  }
  return Status::Ok();
}

// Buffers output and hands it to a file in large chunks.
class FileWriter {
 public:
  explicit FileWriter(const std::string& path)
      : path_(path), file_(path, std::ios::binary | std::ios::trunc) {}

  Status OpenStatus() const {
    if (file_.is_open()) return Status::Ok();
    const int error = errno;
    const std::string message = "cannot open " + path_ + " for writing: " + std::strerror(error);
    return error == ENOENT || error == ENOTDIR ? Status::NotFound(message)
                                               : Status::Internal(message);
  }
  std::string* buffer() { return &buffer_; }
  void FlushIfLarge() {
    constexpr std::size_t kChunk = 1 << 20;
    if (buffer_.size() >= kChunk) Flush();
  }
  Status Close() {
    Flush();
    file_.close();
    if (file_.fail()) {
      return Status::Internal("writing " + path_ + " failed: " + std::strerror(errno));
    }
    return Status::Ok();
  }

 private:
  void Flush() {
    file_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

  std::string path_;
  std::ofstream file_;
  std::string buffer_;
};

void WriteObj(const TriangleMesh& mesh, FileWriter* writer) {
  std::string* out = writer->buffer();
  *out += "# deformd mesh: " + std::to_string(mesh.num_vertices()) + " vertices, " +
          std::to_string(mesh.num_triangles()) + " triangles\n";
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    *out += 'v';
    for (int axis = 0; axis < 3; ++axis) {
      *out += ' ';
      AppendReal(out, mesh.vertices(v, axis));
    }
    *out += '\n';
    writer->FlushIfLarge();
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    *out += 'f';
    for (int c = 0; c < 3; ++c) {
      *out += ' ';
      AppendInteger(out, mesh.triangles(t, c) + 1);
    }
    *out += '\n';
    writer->FlushIfLarge();
  }
}

void WriteOff(const TriangleMesh& mesh, FileWriter* writer) {
  std::string* out = writer->buffer();
  *out += "OFF\n" + std::to_string(mesh.num_vertices()) + " " +
          std::to_string(mesh.num_triangles()) + " 0\n";
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (axis > 0) *out += ' ';
      AppendReal(out, mesh.vertices(v, axis));
    }
    *out += '\n';
    writer->FlushIfLarge();
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    *out += '3';
    for (int c = 0; c < 3; ++c) {
      *out += ' ';
      AppendInteger(out, mesh.triangles(t, c));
    }
    *out += '\n';
    writer->FlushIfLarge();
  }
}

// Binary little-endian PLY with double positions (lossless).
void WritePly(const TriangleMesh& mesh, FileWriter* writer) {
  std::string* out = writer->buffer();
  *out += "ply\nformat binary_little_endian 1.0\ncomment written by deformd\nelement vertex " +
          std::to_string(mesh.num_vertices()) +
          "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
          std::to_string(mesh.num_triangles()) +
          "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(out, mesh.vertices(v, axis));
    writer->FlushIfLarge();
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    AppendLittleEndian(out, std::uint8_t{3});
    for (int c = 0; c < 3; ++c) AppendLittleEndian(out, std::int32_t{mesh.triangles(t, c)});
    writer->FlushIfLarge();
  }
}

// Binary STL (float positions, per-facet unit normals; unreferenced vertices are lost).
void WriteStl(const TriangleMesh& mesh, FileWriter* writer) {
  std::string* out = writer->buffer();
  std::string header = "binary STL written by deformd";  // must not start with "solid"
  header.resize(80, ' ');
  *out += header;
  AppendLittleEndian(out, static_cast<std::uint32_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    Eigen::Matrix3f corners;
    for (int c = 0; c < 3; ++c) {
      corners.row(c) = mesh.vertices.row(mesh.triangles(t, c)).cast<float>();
    }
    Eigen::Vector3f normal =
        (corners.row(1) - corners.row(0)).cross(corners.row(2) - corners.row(0)).transpose();
    const float length = normal.norm();
    normal = length > 0.0f ? Eigen::Vector3f(normal / length) : Eigen::Vector3f::Zero();
    for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(out, normal[axis]);
    for (int c = 0; c < 3; ++c) {
      for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(out, corners(c, axis));
    }
    AppendLittleEndian(out, std::uint16_t{0});
    writer->FlushIfLarge();
  }
}

// Each format's writer.
struct FormatWriter {
  MeshFormat format;
  void (*write)(const TriangleMesh& mesh, FileWriter* writer);
};

constexpr FormatWriter kWriters[] = {{MeshFormat::kObj, &WriteObj},
                                     {MeshFormat::kPly, &WritePly},
                                     {MeshFormat::kStl, &WriteStl},
                                     {MeshFormat::kOff, &WriteOff}};

}  // namespace

Status WriteMeshAs(const TriangleMesh& mesh, MeshFormat format, const std::string& path) {
  const Status writable = CheckWritable(mesh);
  if (!writable.ok()) return writable.WithContext("cannot write " + path);
  const auto writer_of_format =
      std::find_if(std::begin(kWriters), std::end(kWriters),
                   [format](const FormatWriter& writer) { return writer.format == format; });
  if (writer_of_format == std::end(kWriters)) {
    return Status::InvalidArgument("cannot write " + path + ": unknown mesh format");
  }
  FileWriter writer(path);
  DEFORM_RETURN_IF_ERROR(writer.OpenStatus());
  writer_of_format->write(mesh, &writer);
  return writer.Close();
}

}  // namespace deform::mesh_io_internal
