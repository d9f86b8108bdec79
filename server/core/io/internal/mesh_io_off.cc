// Reading OFF data: the checks that come before OpenMesh's OFF reader, and the read.
//
// OpenMesh's OFF reader reserves memory for the declared counts and loops over the declared face
// count without checking for the end of input, so a short file with a large count spins and
// allocates without bound (garbage input threw std::bad_alloc); unparsable numbers are read as
// stale values. So the whole text is walked here first, token by token exactly as the reader
// reads it: only plain ASCII "OFF" (no colours, normals, comments or binary variant).
#include <algorithm>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>

#include "mesh_io_internal.h"
#include "mesh_soup_importer.h"

namespace deform::mesh_io_internal {
namespace {

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
    DEFORM_RETURN_IF_ERROR(ParseVertexCoordinate(token, v, "OFF", tokens->line(), &value));
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
  return CountFaceTriangles(size, "the OFF data", limits_.max_triangles, &num_triangles_);
}

}  // namespace

Status ReadOff(std::string_view text, const MeshLimits& limits, SoupImporter* importer) {
  OffChecker checker(text, limits);
  DEFORM_RETURN_IF_ERROR(checker.Run());
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(text, MeshFormat::kOff, false, importer));
  return CheckImportedCounts(*importer, MeshFormat::kOff, checker.num_vertices(),
                             checker.num_faces());
}

}  // namespace deform::mesh_io_internal
