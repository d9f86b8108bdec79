// Reading goes through OpenMesh's readers into a "polygon soup" importer that records raw
// positions and face index lists (a halfedge mesh would silently drop non-manifold faces before
// validation could see them). OpenMesh's readers trust their input: on malformed data they hang,
// allocate without bound, assert, crash or silently misread (see the notes on each Check*/
// Sanitize* function below). So every format is first walked here, without allocating in
// proportion to any declared count, and only input whose meaning OpenMesh reads unambiguously is
// handed on. Writing is done directly (simple, lossless, and independent of halfedge topology).
#include "core/mesh_io.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <istream>
#include <limits>
#include <locale>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <streambuf>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

// OpenMesh's MeshIO.hh must come before any mesh kernel header, or its readers do not register.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>

namespace deform {
namespace {

// ---------------------------------------------------------------------------------------------
// Text helpers

bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && IsSpace(text.front())) text.remove_prefix(1);
  while (!text.empty() && IsSpace(text.back())) text.remove_suffix(1);
  return text;
}

char ToLower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (ToLower(a[i]) != ToLower(b[i])) return false;
  }
  return true;
}

bool StartsWithIgnoreCase(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && EqualsIgnoreCase(text.substr(0, prefix.size()), prefix);
}

// A token quoted for an error message: shortened, with unprintable bytes replaced.
std::string Quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 32;
  std::string shown(token.substr(0, kMaxShown));
  for (char& c : shown) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  if (token.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

void SplitTokens(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && IsSpace(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !IsSpace(line[pos])) ++pos;
    if (pos > start) tokens->push_back(line.substr(start, pos - start));
  }
}

// Lines split at '\n' (a trailing '\r' is dropped), numbered from 1.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    *line = text_.substr(pos_, end - pos_);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos_ = std::min(end + 1, text_.size());
    ++line_number_;
    return true;
  }
  int line_number() const { return line_number_; }
  // Offset just past the last line returned (and its '\n').
  std::size_t position() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_number_ = 0;
};

// Whitespace-separated tokens across lines, as `std::istream >> x` sees them.
class TokenReader {
 public:
  TokenReader(std::string_view text, int first_line) : text_(text), line_(first_line) {}

  bool Next(std::string_view* token) {
    while (pos_ < text_.size() && IsSpace(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ == text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !IsSpace(text_[pos_])) ++pos_;
    *token = text_.substr(start, pos_ - start);
    return true;
  }
  // Consumes the rest of the current line, as std::getline would; true if it was blank.
  bool SkipRestOfLine() {
    bool blank = true;
    while (pos_ < text_.size() && text_[pos_] != '\n') {
      if (!IsSpace(text_[pos_])) blank = false;
      ++pos_;
    }
    if (pos_ < text_.size()) {
      ++pos_;
      ++line_;
    }
    return blank;
  }
  // Line of the last token read.
  int line() const { return line_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_;
};

// ---------------------------------------------------------------------------------------------
// Numbers as the OpenMesh text readers (std::istream >>) accept them

bool ParseInteger(std::string_view token, long long* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, *value);
  return error == std::errc() && stop == end;
}

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// [+-] digits [. digits] [e [+-] digits], with digits on at least one side of the point.
bool IsDecimalSyntax(std::string_view t) {
  std::size_t i = 0;
  const auto skip_digits = [&t, &i] {
    const std::size_t start = i;
    while (i < t.size() && IsDigit(t[i])) ++i;
    return i - start;
  };
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  std::size_t mantissa_digits = skip_digits();
  if (i < t.size() && t[i] == '.') {
    ++i;
    mantissa_digits += skip_digits();
  }
  if (mantissa_digits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    if (skip_digits() == 0) return false;
  }
  return i == t.size();
}

bool IsNonFiniteWord(std::string_view token) {
  if (!token.empty() && (token.front() == '+' || token.front() == '-')) token.remove_prefix(1);
  return EqualsIgnoreCase(token, "nan") || EqualsIgnoreCase(token, "inf") ||
         EqualsIgnoreCase(token, "infinity") || StartsWithIgnoreCase(token, "nan(");
}

enum class RealParse { kOk, kNonFinite, kMalformed };

// Parses a decimal number. Magnitudes beyond float range count as non-finite: OpenMesh keeps
// positions as floats, and its text readers fail on such values.
RealParse ParseReal(std::string_view token, double* value) {
  if (IsNonFiniteWord(token)) return RealParse::kNonFinite;
  if (!IsDecimalSyntax(token)) return RealParse::kMalformed;
  if (token.front() == '+') token.remove_prefix(1);
  double parsed = 0.0;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, parsed);
  if (error == std::errc::result_out_of_range) {
    // from_chars reports underflow like overflow; underflow reads as (nearly) zero.
    std::istringstream stream{std::string(token)};
    stream.imbue(std::locale::classic());
    stream >> parsed;
    if (stream.fail()) return RealParse::kNonFinite;
  } else if (error != std::errc() || stop != end) {
    return RealParse::kMalformed;
  }
  if (!(std::fabs(parsed) <= FLT_MAX)) return RealParse::kNonFinite;
  *value = parsed;
  return RealParse::kOk;
}

void AppendReal(std::string* out, double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, error == std::errc() ? end : buffer);
}

void AppendInteger(std::string* out, long long value) {
  char buffer[24];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, error == std::errc() ? end : buffer);
}

const char* FormatLabel(MeshFormat format) {
  switch (format) {
    case MeshFormat::kObj:
      return "OBJ";
    case MeshFormat::kPly:
      return "PLY";
    case MeshFormat::kStl:
      return "STL";
    case MeshFormat::kOff:
      return "OFF";
  }
  return "mesh";
}

// ---------------------------------------------------------------------------------------------
// The polygon soup importer

// Raw positions and faces exactly as a reader delivered them.
struct PolygonSoup {
  std::vector<double> coordinates;             // x, y, z per vertex
  std::vector<int> corners;                    // the vertex indices of all faces, face by face
  std::vector<std::size_t> face_starts = {0};  // face f is corners[face_starts[f], [f + 1])

  std::size_t num_vertices() const { return coordinates.size() / 3; }
  std::size_t num_faces() const { return face_starts.size() - 1; }
};

// Records what an OpenMesh reader delivers, with no topology and no checks, so that validation
// sees every face. Stops storing (and flags it) once `limits` are exceeded, so that memory stays
// bounded whatever a reader does. Attributes (normals, colours, texture coordinates) are ignored.
class SoupImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VertexHandle = OpenMesh::VertexHandle;
  using FaceHandle = OpenMesh::FaceHandle;
  using HalfedgeHandle = OpenMesh::HalfedgeHandle;
  using EdgeHandle = OpenMesh::EdgeHandle;
  using Vec2f = OpenMesh::Vec2f;
  using Vec3f = OpenMesh::Vec3f;
  using Vec3d = OpenMesh::Vec3d;
  using Vec3uc = OpenMesh::Vec3uc;
  using Vec4uc = OpenMesh::Vec4uc;
  using Vec4f = OpenMesh::Vec4f;
  using StatusInfo = OpenMesh::Attributes::StatusInfo;

  explicit SoupImporter(const MeshLimits& limits) : limits_(limits) {}

  const PolygonSoup& soup() const { return soup_; }
  bool exceeded_vertex_limit() const { return exceeded_vertex_limit_; }
  bool exceeded_triangle_limit() const { return exceeded_triangle_limit_; }

  VertexHandle add_vertex(const Vec3f& p) override { return AddVertex(p[0], p[1], p[2]); }
  VertexHandle add_vertex(const Vec3d& p) override { return AddVertex(p[0], p[1], p[2]); }
  VertexHandle add_vertex() override { return AddVertex(0.0, 0.0, 0.0); }
  void set_point(VertexHandle vh, const Vec3f& p) override {
    if (vh.idx() < 0 || static_cast<std::size_t>(vh.idx()) >= soup_.num_vertices()) return;
    double* xyz = &soup_.coordinates[3 * static_cast<std::size_t>(vh.idx())];
    xyz[0] = p[0];
    xyz[1] = p[1];
    xyz[2] = p[2];
  }
  FaceHandle add_face(const VHandles& handles) override;

  void reserve(unsigned int num_vertices, unsigned int, unsigned int num_faces) override {
    soup_.coordinates.reserve(3 * std::min<std::size_t>(num_vertices, limits_.max_vertices));
    soup_.face_starts.reserve(1 + std::min<std::size_t>(num_faces, limits_.max_triangles));
  }
  size_t n_vertices() const override { return num_vertices_seen_; }
  size_t n_faces() const override { return num_faces_seen_; }
  size_t n_edges() const override { return 0; }

  // Everything below is deliberately ignored.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_status(EdgeHandle, const StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

 private:
  VertexHandle AddVertex(double x, double y, double z);

  MeshLimits limits_;
  PolygonSoup soup_;
  std::size_t num_vertices_seen_ = 0;
  std::size_t num_faces_seen_ = 0;
  std::size_t num_triangles_seen_ = 0;
  bool exceeded_vertex_limit_ = false;
  bool exceeded_triangle_limit_ = false;
};

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

// Fan-triangulates the soup. Faces with fewer than three corners and out-of-range indices are
// reported with the file's (0-based) face number.
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

// Precondition: `bytes` passed the format's checks below. `binary` selects binary STL.
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

Status DeclaresTooMany(std::string_view header, std::uint64_t count, std::string_view noun,
                       std::size_t limit) {
  return Status::ResourceExhausted(std::string(header) + " declares " + std::to_string(count) +
                                   " " + std::string(noun) + "; the limit is " +
                                   std::to_string(limit));
}

Status TooManyVertices(std::string_view what, std::size_t limit) {
  return Status::ResourceExhausted(std::string(what) + " has more than " + std::to_string(limit) +
                                   " vertices (the limit)");
}

Status TooManyTriangles(std::string_view what, std::size_t limit) {
  return Status::ResourceExhausted(std::string(what) + " has more than " + std::to_string(limit) +
                                   " triangles (the limit)");
}

Status NonFiniteCoordinate(std::size_t vertex, std::string_view token, std::string_view where) {
  return Status::InvalidArgument("vertex " + std::to_string(vertex) +
                                 " has a non-finite coordinate (" + Quoted(token) + ", " +
                                 std::string(where) + ")");
}

// ---------------------------------------------------------------------------------------------
// OBJ
//
// OpenMesh's OBJ reader skips a `v` line it cannot parse (nan, inf, overflow), which shifts every
// later index; skips face indices it cannot parse; asserts (aborts) on a face corner without a
// vertex index ("f /1 /2 /3"); opens any path named by `mtllib`; and silently drops repeated
// corners. So the text is checked here and only `v` and `f` lines go on to OpenMesh, rewritten
// canonically (shortest round-trip numbers, absolute 1-based indices).

class ObjSanitizer {
 public:
  explicit ObjSanitizer(const MeshLimits& limits) : limits_(limits) {}

  // The canonical text on success.
  StatusOr<std::string> Run(std::string_view text);
  std::size_t num_vertices() const { return num_vertices_; }
  std::size_t num_faces() const { return num_faces_; }

 private:
  Status AddVertex();
  Status AddFace();
  StatusOr<long long> ResolveCorner(std::string_view corner) const;
  Status LineError(const std::string& message) const {
    return Status::InvalidArgument("OBJ line " + std::to_string(line_) + ": " + message);
  }

  MeshLimits limits_;
  std::string output_;
  std::vector<std::string_view> tokens_;
  std::vector<long long> face_;
  std::size_t num_vertices_ = 0;
  std::size_t num_faces_ = 0;
  std::size_t num_triangles_ = 0;
  long long largest_index_ = 0;
  int largest_index_line_ = 0;
  int line_ = 0;
};

StatusOr<std::string> ObjSanitizer::Run(std::string_view text) {
  LineReader lines(text);
  std::string_view line;
  while (lines.Next(&line)) {
    line_ = lines.line_number();
    SplitTokens(line, &tokens_);
    if (tokens_.empty()) continue;
    if (tokens_[0] == "v") DEFORM_RETURN_IF_ERROR(AddVertex());
    if (tokens_[0] == "f") DEFORM_RETURN_IF_ERROR(AddFace());
  }
  if (largest_index_ > static_cast<long long>(num_vertices_)) {
    line_ = largest_index_line_;
    return LineError("face references vertex " + std::to_string(largest_index_) +
                     " but the file has " + std::to_string(num_vertices_) + " vertices");
  }
  return std::move(output_);
}

Status ObjSanitizer::AddVertex() {
  if (num_vertices_ == limits_.max_vertices)
    return TooManyVertices("the OBJ data", limits_.max_vertices);
  if (tokens_.size() < 4) return LineError("a vertex needs three coordinates");
  output_ += 'v';
  for (std::size_t i = 1; i <= 3; ++i) {
    double value = 0.0;
    switch (ParseReal(tokens_[i], &value)) {
      case RealParse::kOk:
        break;
      case RealParse::kNonFinite:
        return NonFiniteCoordinate(num_vertices_, tokens_[i], "OBJ line " + std::to_string(line_));
      case RealParse::kMalformed:
        return LineError("vertex " + std::to_string(num_vertices_) + " has a coordinate that is " +
                         "not a number: " + Quoted(tokens_[i]));
    }
    output_ += ' ';
    AppendReal(&output_, value);
  }
  output_ += '\n';
  ++num_vertices_;
  return Status::Ok();
}

// A corner is "v", "v/vt", "v//vn" or "v/vt/vn"; returns v as an absolute 1-based index (not
// yet checked against the final vertex count, which forward references may need).
StatusOr<long long> ObjSanitizer::ResolveCorner(std::string_view corner) const {
  if (std::count(corner.begin(), corner.end(), '/') > 2) {
    return LineError("face corner " + Quoted(corner) + " has more than three parts");
  }
  long long index = 0;
  const std::string_view vertex_part = corner.substr(0, corner.find('/'));
  if (!ParseInteger(vertex_part, &index) || index < std::numeric_limits<int>::min() ||
      index > std::numeric_limits<int>::max()) {
    return LineError("face corner " + Quoted(corner) + " has no valid vertex index");
  }
  if (index == 0) return LineError("vertex index 0 is invalid (OBJ indices start at 1)");
  if (index > 0) return index;
  const long long resolved = static_cast<long long>(num_vertices_) + index + 1;
  if (resolved < 1) {
    return LineError("relative vertex index " + std::to_string(index) + " reaches before the " +
                     "first vertex (" + std::to_string(num_vertices_) + " vertices so far)");
  }
  return resolved;
}

Status ObjSanitizer::AddFace() {
  if (tokens_.size() < 4) return LineError("a face needs at least 3 vertices");
  face_.clear();
  for (std::size_t i = 1; i < tokens_.size(); ++i) {
    DEFORM_ASSIGN_OR_RETURN(const long long index, ResolveCorner(tokens_[i]));
    face_.push_back(index);
    if (index > largest_index_) {
      largest_index_ = index;
      largest_index_line_ = line_;
    }
  }
  std::vector<long long> sorted = face_;
  std::sort(sorted.begin(), sorted.end());
  const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
  if (repeated != sorted.end()) {
    return LineError("face uses vertex " + std::to_string(*repeated) +
                     " more than once (degenerate)");
  }
  num_triangles_ += face_.size() - 2;
  if (num_triangles_ > limits_.max_triangles) {
    return TooManyTriangles("the OBJ data", limits_.max_triangles);
  }
  output_ += 'f';
  for (const long long index : face_) {
    output_ += ' ';
    AppendInteger(&output_, index);
  }
  output_ += '\n';
  ++num_faces_;
  return Status::Ok();
}

Status ReadObj(std::string_view text, const MeshLimits& limits, SoupImporter* importer) {
  ObjSanitizer sanitizer(limits);
  DEFORM_ASSIGN_OR_RETURN(const std::string canonical, sanitizer.Run(text));
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(canonical, MeshFormat::kObj, false, importer));
  return CheckImportedCounts(*importer, MeshFormat::kObj, sanitizer.num_vertices(),
                             sanitizer.num_faces());
}

// ---------------------------------------------------------------------------------------------
// OFF
//
// OpenMesh's OFF reader reserves memory for the declared counts and loops over the declared face
// count without checking for the end of input, so a short file with a large count spins and
// allocates without bound (garbage input threw std::bad_alloc); unparsable numbers are read as
// stale values. So the whole text is walked here first, token by token exactly as the reader
// reads it: only plain ASCII "OFF" (no colours, normals, comments or binary variant).

class OffChecker {
 public:
  OffChecker(std::string_view text, const MeshLimits& limits) : text_(text), limits_(limits) {}

  Status Run();
  std::size_t num_vertices() const { return num_vertices_; }
  std::size_t num_faces() const { return num_faces_; }

 private:
  Status ReadCounts(TokenReader* tokens);
  Status CheckVertex(TokenReader* tokens, std::size_t v);
  Status CheckFace(TokenReader* tokens, std::size_t f);
  Status LineError(const TokenReader& tokens, const std::string& message) const {
    return Status::InvalidArgument("OFF line " + std::to_string(tokens.line()) + ": " + message);
  }

  std::string_view text_;
  MeshLimits limits_;
  std::size_t num_vertices_ = 0;
  std::size_t num_faces_ = 0;
  std::size_t num_triangles_ = 0;
};

Status OffChecker::Run() {
  LineReader lines(text_);
  std::string_view header;
  lines.Next(&header);
  if (Trim(header) != "OFF") {
    return Status::InvalidArgument(
        "the first OFF line must be exactly 'OFF' (variants such as COFF, NOFF or OFF BINARY, "
        "and counts on the first line, are not supported); found " +
        Quoted(Trim(header)));
  }
  TokenReader tokens(text_.substr(lines.position()), 2);
  DEFORM_RETURN_IF_ERROR(ReadCounts(&tokens));
  for (std::size_t v = 0; v < num_vertices_; ++v) DEFORM_RETURN_IF_ERROR(CheckVertex(&tokens, v));
  for (std::size_t f = 0; f < num_faces_; ++f) DEFORM_RETURN_IF_ERROR(CheckFace(&tokens, f));
  return Status::Ok();
}

Status OffChecker::ReadCounts(TokenReader* tokens) {
  long long counts[3] = {0, 0, 0};
  for (long long& count : counts) {
    std::string_view token;
    if (!tokens->Next(&token) || !ParseInteger(token, &count) || count < 0) {
      return Status::InvalidArgument(
          "the OFF header needs vertex, face and edge counts (non-negative integers)");
    }
  }
  num_vertices_ = static_cast<std::size_t>(counts[0]);
  num_faces_ = static_cast<std::size_t>(counts[1]);
  if (num_vertices_ > limits_.max_vertices) {
    return DeclaresTooMany("the OFF header", num_vertices_, "vertices", limits_.max_vertices);
  }
  if (num_faces_ > limits_.max_triangles) {
    return DeclaresTooMany("the OFF header", num_faces_, "faces", limits_.max_triangles);
  }
  // The reader keeps counts in an unsigned int.
  if (*std::max_element(std::begin(counts), std::end(counts)) >
      std::numeric_limits<unsigned int>::max()) {
    return Status::InvalidArgument("the OFF header's counts are too large");
  }
  return Status::Ok();
}

Status OffChecker::CheckVertex(TokenReader* tokens, std::size_t v) {
  for (int axis = 0; axis < 3; ++axis) {
    std::string_view token;
    if (!tokens->Next(&token)) {
      return Status::InvalidArgument("the OFF data ends inside vertex " + std::to_string(v) +
                                     " of " + std::to_string(num_vertices_));
    }
    double value = 0.0;
    switch (ParseReal(token, &value)) {
      case RealParse::kOk:
        break;
      case RealParse::kNonFinite:
        return NonFiniteCoordinate(v, token, "OFF line " + std::to_string(tokens->line()));
      case RealParse::kMalformed:
        return LineError(*tokens, "vertex " + std::to_string(v) +
                                      " has a coordinate that is not a number: " + Quoted(token));
    }
  }
  tokens->SkipRestOfLine();  // The reader ignores the rest of a vertex line.
  return Status::Ok();
}

Status OffChecker::CheckFace(TokenReader* tokens, std::size_t f) {
  const auto ends_inside = [&] {
    return Status::InvalidArgument("the OFF data ends inside face " + std::to_string(f) + " of " +
                                   std::to_string(num_faces_));
  };
  std::string_view token;
  long long size = 0;
  if (!tokens->Next(&token)) return ends_inside();
  if (!ParseInteger(token, &size) || size < 0 || size > std::numeric_limits<int>::max()) {
    return LineError(*tokens,
                     "face " + std::to_string(f) + " has an invalid vertex count " + Quoted(token));
  }
  for (long long i = 0; i < size; ++i) {
    long long index = 0;
    if (!tokens->Next(&token)) return ends_inside();
    if (!ParseInteger(token, &index) || index < std::numeric_limits<int>::min() ||
        index > std::numeric_limits<int>::max()) {
      return LineError(
          *tokens, "face " + std::to_string(f) + " has an invalid vertex index " + Quoted(token));
    }
  }
  if (!tokens->SkipRestOfLine()) {
    return LineError(*tokens, "face " + std::to_string(f) + " has values after its " +
                                  std::to_string(size) +
                                  " vertex indices (face colours are not supported)");
  }
  num_triangles_ += size > 3 ? static_cast<std::size_t>(size - 2) : 1;
  if (num_triangles_ > limits_.max_triangles) {
    return TooManyTriangles("the OFF data", limits_.max_triangles);
  }
  return Status::Ok();
}

Status ReadOff(std::string_view text, const MeshLimits& limits, SoupImporter* importer) {
  OffChecker checker(text, limits);
  DEFORM_RETURN_IF_ERROR(checker.Run());
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(text, MeshFormat::kOff, false, importer));
  return CheckImportedCounts(*importer, MeshFormat::kOff, checker.num_vertices(),
                             checker.num_faces());
}

// ---------------------------------------------------------------------------------------------
// PLY
//
// OpenMesh's PLY reader loops forever on a header without "end_header" or with an unparsable
// element count (it stops only on a stream error, and keeps appending elements); crashes on a
// "property" line before any "element"; loops over declared counts while the input has run out;
// reads list properties outside the face's vertex_indices/texcoord as single values
// (desynchronising the rest); skips face properties declared before vertex_indices; and leaves a
// value unread when a known property (colour, normal, ...) has a type it cannot convert. It
// supports list counts of uchar/uint8/uint16/int only, and finds the binary body by assuming
// exactly one newline around "end_header". So the header is parsed here, checked against what
// the reader handles, the body walked, and OpenMesh is given a canonical header (one property
// per line, no comments, list counts renamed to the supported type of the same size, elements
// after the face element dropped since the reader never reads them) followed by the body.

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> PlyTypeFromName(std::string_view name) {
  static const std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [type_name, type] : kNames) {
    if (name == type_name) return type;
  }
  return std::nullopt;
}

std::size_t PlyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 1;
}

bool IsPlyInteger(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }
bool IsPlySigned(PlyType type) {
  return type == PlyType::kInt8 || type == PlyType::kInt16 || type == PlyType::kInt32;
}

struct PlyProperty {
  std::string name;
  std::string type_name;  // a scalar's type, or a list's entry type, as written
  PlyType type = PlyType::kFloat32;
  std::optional<PlyType> count_type;  // set for a list
  bool is_list() const { return count_type.has_value(); }
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
};

bool IsVertexIndexList(const PlyElement& element, const PlyProperty& property) {
  return element.name == "face" && property.is_list() &&
         (property.name == "vertex_indices" || property.name == "vertex_index");
}

class PlyHeaderParser {
 public:
  explicit PlyHeaderParser(std::string_view bytes) : lines_(bytes) {}
  StatusOr<PlyHeader> Run();

 private:
  Status ParseFormat();
  Status ParseElement();
  Status ParseProperty();
  Status LineError(const std::string& message) const {
    return Status::InvalidArgument("PLY header line " + std::to_string(lines_.line_number()) +
                                   ": " + message);
  }

  LineReader lines_;
  std::vector<std::string_view> tokens_;
  PlyHeader header_;
  bool has_format_ = false;
};

StatusOr<PlyHeader> PlyHeaderParser::Run() {
  std::string_view line;
  lines_.Next(&line);
  if (Trim(line) != "ply" && Trim(line) != "PLY") {
    return Status::InvalidArgument("not PLY data: the first line is not 'ply'");
  }
  while (lines_.Next(&line)) {
    SplitTokens(line, &tokens_);
    if (tokens_.empty() || tokens_[0] == "comment" || tokens_[0] == "obj_info") continue;
    if (tokens_[0] == "end_header") {
      if (tokens_.size() != 1) return LineError("'end_header' must stand alone on its line");
      if (!has_format_) return Status::InvalidArgument("the PLY header has no 'format' line");
      header_.body_offset = lines_.position();
      return std::move(header_);
    }
    if (tokens_[0] == "format") {
      DEFORM_RETURN_IF_ERROR(ParseFormat());
    } else if (tokens_[0] == "element") {
      DEFORM_RETURN_IF_ERROR(ParseElement());
    } else if (tokens_[0] == "property") {
      DEFORM_RETURN_IF_ERROR(ParseProperty());
    } else {
      return LineError("unknown keyword " + Quoted(tokens_[0]));
    }
  }
  return Status::InvalidArgument("the PLY header has no 'end_header' line");
}

Status PlyHeaderParser::ParseFormat() {
  if (tokens_.size() != 3) return LineError("expected 'format <encoding> 1.0'");
  if (tokens_[1] == "ascii") {
    header_.encoding = PlyEncoding::kAscii;
  } else if (tokens_[1] == "binary_little_endian") {
    header_.encoding = PlyEncoding::kBinaryLittleEndian;
  } else if (tokens_[1] == "binary_big_endian") {
    header_.encoding = PlyEncoding::kBinaryBigEndian;
  } else {
    return LineError("unknown PLY encoding " + Quoted(tokens_[1]));
  }
  has_format_ = true;
  return Status::Ok();
}

Status PlyHeaderParser::ParseElement() {
  long long count = 0;
  if (tokens_.size() != 3 || !ParseInteger(tokens_[2], &count) || count < 0) {
    return LineError("expected 'element <name> <count>' with a non-negative count");
  }
  PlyElement element;
  element.name = std::string(tokens_[1]);
  element.count = static_cast<std::uint64_t>(count);
  header_.elements.push_back(std::move(element));
  return Status::Ok();
}

Status PlyHeaderParser::ParseProperty() {
  if (header_.elements.empty()) return LineError("a property comes before any element");
  const bool is_list = tokens_.size() >= 2 && tokens_[1] == "list";
  if (tokens_.size() != (is_list ? 5u : 3u)) {
    return LineError("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
  }
  PlyProperty property;
  property.name = std::string(tokens_.back());
  property.type_name = std::string(tokens_[tokens_.size() - 2]);
  const std::optional<PlyType> type = PlyTypeFromName(property.type_name);
  if (!type) return LineError("unknown type " + Quoted(property.type_name));
  property.type = *type;
  if (is_list) {
    property.count_type = PlyTypeFromName(tokens_[2]);
    if (!property.count_type || !IsPlyInteger(*property.count_type)) {
      return LineError("a list count needs an integer type, not " + Quoted(tokens_[2]));
    }
  }
  std::vector<PlyProperty>& properties = header_.elements.back().properties;
  for (const PlyProperty& existing : properties) {
    if (existing.name == property.name) {
      return LineError("property " + Quoted(property.name) + " is declared twice");
    }
  }
  properties.push_back(std::move(property));
  return Status::Ok();
}

bool IsOneOf(std::string_view name, std::initializer_list<std::string_view> names) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

Status UnsupportedPlyProperty(const PlyElement& element, const PlyProperty& property,
                              const std::string& why) {
  return Status::InvalidArgument("PLY " + element.name + " property " + Quoted(property.name) +
                                 " is not supported: " + why);
}

Status CheckPlyVertexElement(const PlyElement& vertex) {
  for (std::string_view axis : {"x", "y", "z"}) {
    const auto found = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                    [axis](const PlyProperty& p) { return p.name == axis; });
    if (found == vertex.properties.end()) {
      return Status::InvalidArgument("the PLY vertex element has no " + Quoted(axis) + " property");
    }
  }
  for (const PlyProperty& property : vertex.properties) {
    if (property.is_list()) return UnsupportedPlyProperty(vertex, property, "it is a list");
    if (IsOneOf(property.name, {"x", "y", "z", "nx", "ny", "nz", "u", "v", "s", "t"}) &&
        IsPlyInteger(property.type)) {
      return UnsupportedPlyProperty(vertex, property, "it must be float or double");
    }
    if (IsOneOf(property.name, {"red", "green", "blue", "alpha", "diffuse_red", "diffuse_green",
                                "diffuse_blue"}) &&
        property.type == PlyType::kFloat64) {
      return UnsupportedPlyProperty(vertex, property, "a colour cannot be double");
    }
  }
  return Status::Ok();
}

Status CheckPlyFaceElement(const PlyElement& face) {
  if (face.properties.empty() || !IsVertexIndexList(face, face.properties.front())) {
    return Status::InvalidArgument(
        "the PLY face element must start with a 'vertex_indices' list property");
  }
  if (!IsPlyInteger(face.properties.front().type)) {
    return UnsupportedPlyProperty(face, face.properties.front(), "indices must be integers");
  }
  for (std::size_t i = 1; i < face.properties.size(); ++i) {
    const PlyProperty& property = face.properties[i];
    if (property.is_list() && property.name != "texcoord") {
      return UnsupportedPlyProperty(face, property, "it is a list");
    }
    if (IsOneOf(property.name, {"red", "green", "blue", "alpha"}) &&
        property.type == PlyType::kFloat64) {
      return UnsupportedPlyProperty(face, property, "a colour cannot be double");
    }
    if (property.name == "texnumber" && !IsPlyInteger(property.type)) {
      return UnsupportedPlyProperty(face, property, "it must be an integer");
    }
  }
  return Status::Ok();
}

Status CheckPlyOtherElement(const PlyElement& element) {
  for (const PlyProperty& property : element.properties) {
    if (property.is_list()) return UnsupportedPlyProperty(element, property, "it is a list");
  }
  if (element.properties.empty() && element.count > 0) {
    return Status::InvalidArgument("the PLY element " + Quoted(element.name) +
                                   " has no properties");
  }
  return Status::Ok();
}

std::optional<std::size_t> FindPlyElement(const PlyHeader& header, std::string_view name) {
  for (std::size_t i = 0; i < header.elements.size(); ++i) {
    if (header.elements[i].name == name) return i;
  }
  return std::nullopt;
}

// Checks the header against the reader's abilities and `limits`, and drops the elements after
// the face element (which the reader never reads).
Status CheckPlyLayout(const MeshLimits& limits, PlyHeader* header) {
  for (std::size_t i = 0; i < header->elements.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (header->elements[i].name == header->elements[j].name) {
        return Status::InvalidArgument("the PLY element " + Quoted(header->elements[i].name) +
                                       " is declared twice");
      }
    }
  }
  const std::optional<std::size_t> vertex = FindPlyElement(*header, "vertex");
  const std::optional<std::size_t> face = FindPlyElement(*header, "face");
  if (!vertex) return Status::InvalidArgument("the PLY data has no vertex element");
  if (face && *face < *vertex) {
    return Status::InvalidArgument("the PLY face element must come after the vertex element");
  }
  if (header->elements[*vertex].count > limits.max_vertices) {
    return DeclaresTooMany("the PLY header", header->elements[*vertex].count, "vertices",
                           limits.max_vertices);
  }
  if (face && header->elements[*face].count > limits.max_triangles) {
    return DeclaresTooMany("the PLY header", header->elements[*face].count, "faces",
                           limits.max_triangles);
  }
  if (face) header->elements.resize(*face + 1);
  for (std::size_t i = 0; i < header->elements.size(); ++i) {
    const PlyElement& element = header->elements[i];
    // The reader keeps counts in an unsigned int.
    if (element.count > std::numeric_limits<unsigned int>::max()) {
      return Status::InvalidArgument("the PLY element " + Quoted(element.name) +
                                     " has too many records");
    }
    if (i == vertex) {
      DEFORM_RETURN_IF_ERROR(CheckPlyVertexElement(element));
    } else if (i == face) {
      if (element.count > 0) DEFORM_RETURN_IF_ERROR(CheckPlyFaceElement(element));
    } else {
      DEFORM_RETURN_IF_ERROR(CheckPlyOtherElement(element));
    }
  }
  return Status::Ok();
}

// The list count type OpenMesh supports with the same size (counts are checked non-negative).
const char* CanonicalPlyCountType(PlyType type) {
  switch (PlyTypeSize(type)) {
    case 1:
      return "uchar";
    case 2:
      return "uint16";
    default:
      return "int";
  }
}

std::string CanonicalPlyHeader(const PlyHeader& header) {
  std::string text = "ply\nformat ";
  switch (header.encoding) {
    case PlyEncoding::kAscii:
      text += "ascii";
      break;
    case PlyEncoding::kBinaryLittleEndian:
      text += "binary_little_endian";
      break;
    case PlyEncoding::kBinaryBigEndian:
      text += "binary_big_endian";
      break;
  }
  text += " 1.0\n";
  for (const PlyElement& element : header.elements) {
    text += "element " + element.name + " " + std::to_string(element.count) + "\n";
    for (const PlyProperty& property : element.properties) {
      text += "property ";
      if (property.is_list()) {
        text += std::string("list ") + CanonicalPlyCountType(*property.count_type) + " ";
      }
      text += property.type_name + " " + property.name + "\n";
    }
  }
  return text + "end_header\n";
}

// Reads fixed-size integers from a binary PLY body.
class PlyByteReader {
 public:
  PlyByteReader(std::string_view bytes, bool big_endian) : bytes_(bytes), big_endian_(big_endian) {}

  std::size_t remaining() const { return bytes_.size() - pos_; }
  bool Skip(std::uint64_t count) {
    if (count > remaining()) return false;
    pos_ += static_cast<std::size_t>(count);
    return true;
  }
  bool ReadInteger(PlyType type, long long* value) {
    const std::size_t size = PlyTypeSize(type);
    if (size > remaining()) return false;
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const std::size_t byte = big_endian_ ? i : size - 1 - i;
      bits = (bits << 8) | static_cast<unsigned char>(bytes_[pos_ + byte]);
    }
    pos_ += size;
    const std::uint64_t sign_bit = std::uint64_t{1} << (8 * size - 1);
    if (IsPlySigned(type) && (bits & sign_bit)) {
      *value = static_cast<long long>(bits) - static_cast<long long>(sign_bit << 1);
    } else {
      *value = static_cast<long long>(bits);
    }
    return true;
  }

 private:
  std::string_view bytes_;
  bool big_endian_;
  std::size_t pos_ = 0;
};

// Walks a PLY body (binary or ASCII) over the checked header's elements, making sure every
// record is complete and well-formed, that list counts are sane, and counting triangles.
class PlyBodyChecker {
 public:
  PlyBodyChecker(const PlyHeader& header, std::string_view body, const MeshLimits& limits)
      : header_(header), body_(body), limits_(limits) {}

  Status Run() { return header_.encoding == PlyEncoding::kAscii ? CheckAscii() : CheckBinary(); }

 private:
  Status CheckBinary();
  Status CheckBinaryRecord(PlyByteReader* reader, const PlyElement& element, std::uint64_t r);
  Status CheckAscii();
  Status CheckAsciiValue(const PlyElement& element, std::uint64_t r, const PlyProperty& property,
                         PlyType type, std::string_view token) const;
  Status CountFace(long long size);
  Status EndsInside(const PlyElement& element, std::uint64_t r) const {
    return Status::InvalidArgument("the PLY data ends inside " + element.name + " " +
                                   std::to_string(r) + " of " + std::to_string(element.count));
  }

  const PlyHeader& header_;
  std::string_view body_;
  MeshLimits limits_;
  std::size_t num_triangles_ = 0;
};

Status PlyBodyChecker::CountFace(long long size) {
  num_triangles_ += size > 3 ? static_cast<std::size_t>(size - 2) : 1;
  if (num_triangles_ > limits_.max_triangles) {
    return TooManyTriangles("the PLY data", limits_.max_triangles);
  }
  return Status::Ok();
}

Status PlyBodyChecker::CheckBinary() {
  PlyByteReader reader(body_, header_.encoding == PlyEncoding::kBinaryBigEndian);
  for (const PlyElement& element : header_.elements) {
    const bool has_list = std::any_of(element.properties.begin(), element.properties.end(),
                                      [](const PlyProperty& p) { return p.is_list(); });
    if (!has_list) {
      std::uint64_t record_size = 0;
      for (const PlyProperty& property : element.properties) {
        record_size += PlyTypeSize(property.type);
      }
      if (record_size > 0 && element.count > reader.remaining() / record_size) {
        return EndsInside(element, reader.remaining() / record_size);
      }
      reader.Skip(record_size * element.count);
      continue;
    }
    for (std::uint64_t r = 0; r < element.count; ++r) {
      DEFORM_RETURN_IF_ERROR(CheckBinaryRecord(&reader, element, r));
    }
  }
  return Status::Ok();
}

Status PlyBodyChecker::CheckBinaryRecord(PlyByteReader* reader, const PlyElement& element,
                                         std::uint64_t r) {
  for (const PlyProperty& property : element.properties) {
    if (!property.is_list()) {
      if (!reader->Skip(PlyTypeSize(property.type))) return EndsInside(element, r);
      continue;
    }
    long long size = 0;
    if (!reader->ReadInteger(*property.count_type, &size)) return EndsInside(element, r);
    if (size < 0 || size > std::numeric_limits<int>::max()) {
      return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) +
                                     " has an invalid list size " + std::to_string(size));
    }
    if (static_cast<std::uint64_t>(size) > reader->remaining() / PlyTypeSize(property.type)) {
      return EndsInside(element, r);
    }
    reader->Skip(static_cast<std::uint64_t>(size) * PlyTypeSize(property.type));
    if (IsVertexIndexList(element, property)) DEFORM_RETURN_IF_ERROR(CountFace(size));
  }
  return Status::Ok();
}

Status PlyBodyChecker::CheckAsciiValue(const PlyElement& element, std::uint64_t r,
                                       const PlyProperty& property, PlyType type,
                                       std::string_view token) const {
  const auto invalid = [&] {
    return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) + ": property " +
                                   Quoted(property.name) + " has an invalid value " +
                                   Quoted(token));
  };
  if (IsPlyInteger(type)) {
    long long value = 0;
    // The reader extracts some integers into an int.
    const bool ok = ParseInteger(token, &value) && value >= std::numeric_limits<int>::min() &&
                    value <= std::numeric_limits<int>::max();
    return ok ? Status::Ok() : invalid();
  }
  double value = 0.0;
  const RealParse parse = ParseReal(token, &value);
  if (parse == RealParse::kNonFinite && element.name == "vertex" &&
      IsOneOf(property.name, {"x", "y", "z"})) {
    return NonFiniteCoordinate(static_cast<std::size_t>(r), token, "PLY data");
  }
  return parse == RealParse::kOk ? Status::Ok() : invalid();
}

Status PlyBodyChecker::CheckAscii() {
  TokenReader tokens(body_, 1);
  std::string_view token;
  for (const PlyElement& element : header_.elements) {
    for (std::uint64_t r = 0; r < element.count; ++r) {
      for (const PlyProperty& property : element.properties) {
        if (!tokens.Next(&token)) return EndsInside(element, r);
        if (!property.is_list()) {
          DEFORM_RETURN_IF_ERROR(CheckAsciiValue(element, r, property, property.type, token));
          continue;
        }
        long long size = 0;
        if (!ParseInteger(token, &size) || size < 0 || size > std::numeric_limits<int>::max()) {
          return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) +
                                         " has an invalid list size " + Quoted(token));
        }
        for (long long i = 0; i < size; ++i) {
          if (!tokens.Next(&token)) return EndsInside(element, r);
          DEFORM_RETURN_IF_ERROR(CheckAsciiValue(element, r, property, property.type, token));
        }
        if (IsVertexIndexList(element, property)) DEFORM_RETURN_IF_ERROR(CountFace(size));
      }
    }
  }
  return Status::Ok();
}

Status ReadPly(std::string_view bytes, const MeshLimits& limits, SoupImporter* importer) {
  DEFORM_ASSIGN_OR_RETURN(PlyHeader header, PlyHeaderParser(bytes).Run());
  DEFORM_RETURN_IF_ERROR(CheckPlyLayout(limits, &header));
  const std::string_view body = bytes.substr(header.body_offset);
  DEFORM_RETURN_IF_ERROR(PlyBodyChecker(header, body, limits).Run());

  std::string canonical = CanonicalPlyHeader(header);
  canonical.append(body.data(), body.size());
  // The ASCII reader reports "unexpected end of file" if an element ends exactly at the end.
  if (header.encoding == PlyEncoding::kAscii) canonical += '\n';
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(canonical, MeshFormat::kPly, false, importer));
  const std::optional<std::size_t> face = FindPlyElement(header, "face");
  return CheckImportedCounts(*importer, MeshFormat::kPly,
                             header.elements[*FindPlyElement(header, "vertex")].count,
                             face ? static_cast<std::size_t>(header.elements[*face].count) : 0);
}

// ---------------------------------------------------------------------------------------------
// STL
//
// OpenMesh's binary STL reader loops over the declared triangle count (up to 2^32) however short
// the input, and it welds vertices through a std::map whose comparison breaks down on NaN (a
// NaN corner is merged with an arbitrary vertex). The ASCII reader starts a facet at any line
// containing "outer" and reads the next three lines as vertices whatever they hold (a blank or
// malformed line repeats the previous vertex). It welds equal positions, like the binary
// reader, and drops facets whose corners weld together. So the data is checked here first.

constexpr std::size_t kStlHeaderSize = 84;  // 80-byte header and a uint32 triangle count
constexpr std::size_t kStlFacetSize = 50;   // normal, 3 corners (12 floats), uint16 attribute

std::uint32_t ReadLittleEndianU32(const char* bytes) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | static_cast<unsigned char>(bytes[i]);
  return value;
}

float ReadLittleEndianFloat(const char* bytes) {
  const std::uint32_t bits = ReadLittleEndianU32(bytes);
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

enum class StlEncoding { kAscii, kBinary };

StatusOr<StlEncoding> DetectStlEncoding(std::string_view bytes) {
  std::uint64_t declared = 0;
  if (bytes.size() >= kStlHeaderSize) {
    declared = ReadLittleEndianU32(bytes.data() + 80);
    if (kStlHeaderSize + kStlFacetSize * declared == bytes.size()) return StlEncoding::kBinary;
  }
  if (StartsWithIgnoreCase(Trim(bytes), "solid")) return StlEncoding::kAscii;
  if (bytes.size() < kStlHeaderSize) {
    return Status::InvalidArgument(
        "not STL data: no 'solid' line and shorter than the 84-byte binary STL header");
  }
  return Status::InvalidArgument(
      "binary STL data declares " + std::to_string(declared) + " triangles (" +
      std::to_string(kStlHeaderSize + kStlFacetSize * declared) + " bytes) but has " +
      std::to_string(bytes.size()) + " bytes: it is truncated or has trailing data");
}

// Precondition: the size matches the declared count.
Status CheckBinaryStl(std::string_view bytes, const MeshLimits& limits) {
  const std::size_t num_triangles = (bytes.size() - kStlHeaderSize) / kStlFacetSize;
  if (num_triangles > limits.max_triangles) {
    return TooManyTriangles("the STL data", limits.max_triangles);
  }
  for (std::size_t t = 0; t < num_triangles; ++t) {
    const char* corners = bytes.data() + kStlHeaderSize + t * kStlFacetSize + 12;
    for (int i = 0; i < 9; ++i) {
      if (!std::isfinite(ReadLittleEndianFloat(corners + 4 * i))) {
        return Status::InvalidArgument("STL triangle " + std::to_string(t) +
                                       " has a non-finite vertex coordinate");
      }
    }
  }
  return Status::Ok();
}

class AsciiStlChecker {
 public:
  AsciiStlChecker(std::string_view text, const MeshLimits& limits)
      : lines_(text), limits_(limits) {}
  Status Run();

 private:
  Status CheckFacet();
  Status CheckCorner(std::string_view line);
  Status LineError(const std::string& message) const {
    return Status::InvalidArgument("STL line " + std::to_string(lines_.line_number()) + ": " +
                                   message);
  }

  LineReader lines_;
  MeshLimits limits_;
  std::vector<std::string_view> tokens_;
  std::size_t num_facets_ = 0;
};

Status AsciiStlChecker::Run() {
  std::string_view line;
  while (lines_.Next(&line)) {
    const std::string_view trimmed = Trim(line);
    // Exactly the reader's test for the start of a facet.
    if (trimmed.find("outer") != std::string_view::npos ||
        trimmed.find("OUTER") != std::string_view::npos) {
      DEFORM_RETURN_IF_ERROR(CheckFacet());
    }
  }
  return Status::Ok();
}

Status AsciiStlChecker::CheckFacet() {
  if (++num_facets_ > limits_.max_triangles) {
    return TooManyTriangles("the STL data", limits_.max_triangles);
  }
  const std::size_t facet = num_facets_ - 1;
  std::string_view line;
  for (int corner = 0; corner < 3; ++corner) {
    if (!lines_.Next(&line)) {
      return Status::InvalidArgument("the STL data ends inside facet " + std::to_string(facet));
    }
    DEFORM_RETURN_IF_ERROR(CheckCorner(line));
  }
  do {
    if (!lines_.Next(&line)) {
      return Status::InvalidArgument("the STL data ends inside facet " + std::to_string(facet));
    }
  } while (Trim(line).empty());
  // Exactly "endloop": the reader would start another facet at a line containing "outer".
  if (!EqualsIgnoreCase(Trim(line), "endloop")) {
    return LineError("expected 'endloop' after three vertices (facets must be triangles)");
  }
  return Status::Ok();
}

Status AsciiStlChecker::CheckCorner(std::string_view line) {
  SplitTokens(line, &tokens_);
  if (tokens_.size() < 4 || !EqualsIgnoreCase(tokens_[0], "vertex")) {
    return LineError("expected 'vertex <x> <y> <z>'");
  }
  for (std::size_t i = 1; i <= 3; ++i) {
    double value = 0.0;
    switch (ParseReal(tokens_[i], &value)) {
      case RealParse::kOk:
        break;
      case RealParse::kNonFinite:
        return LineError("facet " + std::to_string(num_facets_ - 1) +
                         " has a non-finite vertex coordinate " + Quoted(tokens_[i]));
      case RealParse::kMalformed:
        return LineError("a vertex coordinate is not a number: " + Quoted(tokens_[i]));
    }
  }
  return Status::Ok();
}

Status ReadStl(std::string_view bytes, const MeshLimits& limits, SoupImporter* importer) {
  DEFORM_ASSIGN_OR_RETURN(const StlEncoding encoding, DetectStlEncoding(bytes));
  const bool binary = encoding == StlEncoding::kBinary;
  if (binary) {
    DEFORM_RETURN_IF_ERROR(CheckBinaryStl(bytes, limits));
  } else {
    DEFORM_RETURN_IF_ERROR(AsciiStlChecker(bytes, limits).Run());
  }
  return ReadWithOpenMesh(bytes, MeshFormat::kStl, binary, importer);
}

// ---------------------------------------------------------------------------------------------
// Reading, all formats

StatusOr<TriangleMesh> ReadMeshUnguarded(std::string_view bytes, MeshFormat format,
                                         const MeshLimits& limits) {
  if (bytes.empty()) {
    return Status::InvalidArgument(std::string("the ") + FormatLabel(format) + " data is empty");
  }
  SoupImporter importer(limits);
  switch (format) {
    case MeshFormat::kObj:
      DEFORM_RETURN_IF_ERROR(ReadObj(bytes, limits, &importer));
      break;
    case MeshFormat::kPly:
      DEFORM_RETURN_IF_ERROR(ReadPly(bytes, limits, &importer));
      break;
    case MeshFormat::kStl:
      DEFORM_RETURN_IF_ERROR(ReadStl(bytes, limits, &importer));
      break;
    case MeshFormat::kOff:
      DEFORM_RETURN_IF_ERROR(ReadOff(bytes, limits, &importer));
      break;
  }
  if (importer.exceeded_vertex_limit()) {
    return TooManyVertices(std::string("the ") + FormatLabel(format) + " data",
                           limits.max_vertices);
  }
  if (importer.exceeded_triangle_limit()) {
    return TooManyTriangles(std::string("the ") + FormatLabel(format) + " data",
                            limits.max_triangles);
  }
  DEFORM_ASSIGN_OR_RETURN(TriangleMesh mesh, SoupToMesh(importer.soup()));
  DEFORM_RETURN_IF_ERROR(ValidateMesh(mesh, limits));
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Writing

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

StatusOr<std::string> ReadWholeFile(std::ifstream* file, const std::string& path) {
  std::string bytes;
  file->seekg(0, std::ios::end);
  const std::streamoff size = file->tellg();
  file->seekg(0, std::ios::beg);
  if (size >= 0) {
    bytes.resize(static_cast<std::size_t>(size));
    file->read(bytes.data(), size);
    bytes.resize(static_cast<std::size_t>(file->gcount()));
  } else {  // not seekable (a pipe, say)
    file->clear();
    std::ostringstream contents;
    contents << file->rdbuf();
    bytes = contents.str();
  }
  if (file->bad()) return Status::Internal("reading " + path + " failed");
  return bytes;
}

}  // namespace

StatusOr<MeshFormat> MeshFormatFromName(std::string_view name) {
  std::string_view bare = name;
  if (!bare.empty() && bare.front() == '.') bare.remove_prefix(1);
  for (const MeshFormat format :
       {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff}) {
    if (EqualsIgnoreCase(bare, MeshFormatName(format))) return format;
  }
  return Status::InvalidArgument("unknown mesh format " + Quoted(name) +
                                 " (expected obj, ply, stl or off)");
}

StatusOr<MeshFormat> MeshFormatFromPath(std::string_view path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension.empty()) {
    return Status::InvalidArgument("cannot tell the mesh format of " + Quoted(path) +
                                   ": it has no extension (expected .obj, .ply, .stl or .off)");
  }
  return MeshFormatFromName(extension);
}

const char* MeshFormatName(MeshFormat format) {
  switch (format) {
    case MeshFormat::kObj:
      return "obj";
    case MeshFormat::kPly:
      return "ply";
    case MeshFormat::kStl:
      return "stl";
    case MeshFormat::kOff:
      return "off";
  }
  return "unknown";
}

StatusOr<TriangleMesh> ReadMesh(std::string_view bytes, MeshFormat format,
                                const MeshLimits& limits) {
  try {
    return ReadMeshUnguarded(bytes, format, limits);
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted(std::string("out of memory while reading ") +
                                     FormatLabel(format) + " data");
  } catch (const std::exception& e) {
    return Status::Internal(std::string("reading ") + FormatLabel(format) +
                            " data failed: " + e.what());
  }
}

StatusOr<TriangleMesh> ReadMeshFile(const std::string& path, const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    return Status::InvalidArgument(path + " is a directory, not a mesh file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    return Status::NotFound("cannot open mesh file " + path + ": " + std::strerror(errno));
  }
  std::string bytes;
  try {
    DEFORM_ASSIGN_OR_RETURN(bytes, ReadWholeFile(&file, path));
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted(path + " is too large to read");
  }
  StatusOr<TriangleMesh> mesh = ReadMesh(bytes, format, limits);
  if (!mesh.ok()) return mesh.status().WithContext(path);
  return mesh;
}

Status WriteMeshFile(const TriangleMesh& mesh, const std::string& path) {
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  const Status writable = CheckWritable(mesh);
  if (!writable.ok()) return writable.WithContext("cannot write " + path);
  FileWriter writer(path);
  DEFORM_RETURN_IF_ERROR(writer.OpenStatus());
  switch (format) {
    case MeshFormat::kObj:
      WriteObj(mesh, &writer);
      break;
    case MeshFormat::kPly:
      WritePly(mesh, &writer);
      break;
    case MeshFormat::kStl:
      WriteStl(mesh, &writer);
      break;
    case MeshFormat::kOff:
      WriteOff(mesh, &writer);
      break;
  }
  return writer.Close();
}

}  // namespace deform
