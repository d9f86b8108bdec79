// Reading OBJ data: the checks that come before OpenMesh's OBJ reader, and the read.
//
// OpenMesh's OBJ reader skips a `v` line it cannot parse (nan, inf, overflow), which shifts every
// later index; skips face indices it cannot parse; asserts (aborts) on a face corner without a
// vertex index ("f /1 /2 /3"); opens any path named by `mtllib`; and silently drops repeated
// corners. So the text is checked here and only `v` and `f` lines go on to OpenMesh, rewritten
// canonically (shortest round-trip numbers, absolute 1-based indices).
#include <algorithm>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh_io_internal.h"
#include "mesh_soup_importer.h"

namespace deform::mesh_io_internal {
namespace {

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
    DEFORM_RETURN_IF_ERROR(ParseVertexCoordinate(tokens_[i], num_vertices_, "OBJ", line_, &value));
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
  DEFORM_RETURN_IF_ERROR(CountFaceTriangles(static_cast<long long>(face_.size()), "the OBJ data",
                                            limits_.max_triangles, &num_triangles_));
  output_ += 'f';
  for (const long long index : face_) {
    output_ += ' ';
    AppendInteger(&output_, index);
  }
  output_ += '\n';
  ++num_faces_;
  return Status::Ok();
}

}  // namespace

Status ReadObj(std::string_view text, const MeshLimits& limits, SoupImporter* importer) {
  ObjSanitizer sanitizer(limits);
  DEFORM_ASSIGN_OR_RETURN(const std::string canonical, sanitizer.Run(text));
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(canonical, MeshFormat::kObj, false, importer));
  return CheckImportedCounts(*importer, MeshFormat::kObj, sanitizer.num_vertices(),
                             sanitizer.num_faces());
}

}  // namespace deform::mesh_io_internal
