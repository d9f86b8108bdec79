#include "mesh_soup_importer.h"

#include <spdlog/spdlog.h>

#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <iostream>
#include <istream>
#include <limits>
#include <mutex>
#include <streambuf>
#include <string>
#include <utility>

#include "mesh_io_internal.h"

namespace deform::mesh_io_internal {

SoupImporter::VertexHandle SoupImporter::AddVertex(double x, double y, double z) {
  const int handle = static_cast<int>(std::min<std::size_t>(
      num_vertices_seen_, static_cast<std::size_t>(std::numeric_limits<int>::max())));
  ++num_vertices_seen_;
  if (num_vertices_seen_ > limits_.max_vertices) {
    exceeded_vertex_limit_ = true;
  } else {
    soup_.coordinates.insert(soup_.coordinates.end(), {x, y, z});
  }
  return VertexHandle(handle);
}

SoupImporter::FaceHandle SoupImporter::add_face(const VHandles& handles) {
  const int handle = static_cast<int>(std::min<std::size_t>(
      num_faces_seen_, static_cast<std::size_t>(std::numeric_limits<int>::max())));
  ++num_faces_seen_;
  num_triangles_seen_ += handles.size() > 3 ? handles.size() - 2 : 1;
  if (num_triangles_seen_ > limits_.max_triangles) {
    exceeded_triangle_limit_ = true;
  } else {
    for (const VertexHandle& vh : handles) soup_.corners.push_back(vh.idx());
    soup_.face_starts.push_back(soup_.corners.size());
  }
  return FaceHandle(handle);
}

StatusOr<TriangleMesh> SoupToMesh(const PolygonSoup& soup) {
  const std::size_t num_vertices = soup.num_vertices();
  std::size_t num_triangles = 0;
  for (std::size_t f = 0; f < soup.num_faces(); ++f) {
    const std::size_t size = soup.face_starts[f + 1] - soup.face_starts[f];
    if (size < 3) {
      return Status::InvalidArgument("face " + std::to_string(f) + " has " + std::to_string(size) +
                                     " vertices; at least 3 are needed");
    }
    for (std::size_t i = soup.face_starts[f]; i < soup.face_starts[f + 1]; ++i) {
      const int v = soup.corners[i];
      if (v < 0 || static_cast<std::size_t>(v) >= num_vertices) {
        return Status::InvalidArgument("face " + std::to_string(f) + " references vertex " +
                                       std::to_string(v) + " but the mesh has " +
                                       std::to_string(num_vertices) + " vertices");
      }
    }
    num_triangles += size - 2;
  }
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(num_vertices), 3);
  std::copy(soup.coordinates.begin(), soup.coordinates.end(), mesh.vertices.data());
  mesh.triangles.resize(static_cast<Eigen::Index>(num_triangles), 3);
  Eigen::Index t = 0;
  for (std::size_t f = 0; f < soup.num_faces(); ++f) {
    const std::size_t first = soup.face_starts[f];
    for (std::size_t i = first + 1; i + 1 < soup.face_starts[f + 1]; ++i, ++t) {
      mesh.triangles.row(t) << soup.corners[first], soup.corners[i], soup.corners[i + 1];
    }
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Running an OpenMesh reader

namespace {

// A read-only, seekable std::streambuf over bytes held elsewhere (no copy). OpenMesh's readers
// seek (the OBJ reader makes two passes, the PLY reader seeks to the binary body).
class ViewStreamBuffer : public std::streambuf {
 public:
  explicit ViewStreamBuffer(std::string_view bytes) {
    // The get area is never written through: there is no put area and pbackfail() is not
    // overridden, so the const_cast is safe.
    char* begin = const_cast<char*>(bytes.data());
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type offset, std::ios_base::seekdir direction,
                   std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type size = egptr() - eback();
    off_type base = 0;
    if (direction == std::ios_base::cur) base = gptr() - eback();
    if (direction == std::ios_base::end) base = size;
    const off_type target = base + offset;
    if (target < 0 || target > size) return pos_type(off_type(-1));
    setg(eback(), eback() + target, egptr());
    return pos_type(target);
  }
  pos_type seekpos(pos_type position, std::ios_base::openmode which) override {
    return seekoff(off_type(position), std::ios_base::beg, which);
  }
};

// OpenMesh prints diagnostics on its omerr()/omlog()/omout() streams. On first use these are
// disconnected from the console and connected here: while a read runs (under the IO mutex) the
// text is kept for the returned Status; otherwise it goes to spdlog.
class OpenMeshMessages {
 public:
  static OpenMeshMessages& Instance();

  void StartCapture() {
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_ = true;
    captured_.clear();
  }
  std::string StopCapture() {
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_ = false;
    return std::string(Trim(captured_));
  }
  void Append(const std::string& text, spdlog::level::level_enum level) {
    constexpr std::size_t kMaxCaptured = 2000;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!capturing_) {
      spdlog::log(level, "OpenMesh: {}", Trim(text));
      return;
    }
    if (captured_.size() < kMaxCaptured) {
      if (!captured_.empty()) captured_ += ' ';
      captured_ += std::string(Trim(text)).substr(0, kMaxCaptured);
    }
  }

 private:
  std::mutex mutex_;
  bool capturing_ = false;
  std::string captured_;
};

// One per OpenMesh stream; OpenMesh's multiplexing stream buffer calls operator<< per line.
struct OpenMeshStreamTarget {
  spdlog::level::level_enum level;
  OpenMeshStreamTarget& operator<<(const std::string& text) {
    OpenMeshMessages::Instance().Append(text, level);
    return *this;
  }
};

OpenMeshMessages& OpenMeshMessages::Instance() {
  // Never destroyed: OpenMesh's global streams keep pointers to the targets.
  static OpenMeshMessages* const instance = new OpenMeshMessages();
  static const bool connected = [] {
    static OpenMeshStreamTarget error_target{spdlog::level::warn};
    static OpenMeshStreamTarget log_target{spdlog::level::debug};
    static OpenMeshStreamTarget out_target{spdlog::level::debug};
    const std::pair<OpenMesh::mostream*, OpenMeshStreamTarget*> routes[] = {
        {&::omerr(), &error_target}, {&::omlog(), &log_target}, {&::omout(), &out_target}};
    for (const auto& [stream, target] : routes) {
      stream->disconnect(std::cerr);
      stream->disconnect(std::clog);
      stream->disconnect(std::cout);
      stream->connect(*target);
    }
    return true;
  }();
  static_cast<void>(connected);
  return *instance;
}

// OpenMesh's readers are global singletons with per-read state: one read at a time.
std::mutex& OpenMeshIoMutex() {
  static std::mutex mutex;
  return mutex;
}

class ScopedMessageCapture {
 public:
  ScopedMessageCapture() { OpenMeshMessages::Instance().StartCapture(); }
  ~ScopedMessageCapture() { static_cast<void>(Stop()); }
  std::string Stop() { return OpenMeshMessages::Instance().StopCapture(); }
};

}  // namespace

Status ReadWithOpenMesh(std::string_view bytes, MeshFormat format, bool binary,
                        SoupImporter* importer) {
  ViewStreamBuffer buffer(bytes);
  std::istream stream(&buffer);
  OpenMesh::IO::Options options;
  if (binary) options += OpenMesh::IO::Options::Binary;
  std::lock_guard<std::mutex> lock(OpenMeshIoMutex());
  ScopedMessageCapture capture;
  const bool ok =
      OpenMesh::IO::IOManager().read(stream, MeshFormatName(format), *importer, options);
  const std::string messages = capture.Stop();
  if (!ok) {
    return Status::InvalidArgument(std::string("OpenMesh could not read the ") +
                                   FormatLabel(format) + " data" +
                                   (messages.empty() ? "" : ": " + messages));
  }
  return Status::Ok();
}

Status CheckImportedCounts(const SoupImporter& importer, MeshFormat format,
                           std::size_t expected_vertices, std::size_t expected_faces) {
  if (importer.n_vertices() != expected_vertices || importer.n_faces() != expected_faces) {
    return Status::InvalidArgument(
        std::string("OpenMesh read ") + std::to_string(importer.n_vertices()) + " vertices and " +
        std::to_string(importer.n_faces()) + " faces where the " + FormatLabel(format) +
        " data holds " + std::to_string(expected_vertices) + " and " +
        std::to_string(expected_faces));
  }
  return Status::Ok();
}

}  // namespace deform::mesh_io_internal
