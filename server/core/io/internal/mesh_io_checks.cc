// The error messages and counts that the format checks (mesh_io_<format>.cc) share, so that every
// format reports a limit or a bad coordinate in the same words.
#include <string>
#include <string_view>

#include "mesh_io_internal.h"

namespace deform::mesh_io_internal {

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

Status ParseVertexCoordinate(std::string_view token, std::size_t vertex, std::string_view format,
                             int line, double* value) {
  switch (ParseReal(token, value)) {
    case RealParse::kOk:
      break;
    case RealParse::kNonFinite:
      return NonFiniteCoordinate(vertex, token,
                                 std::string(format) + " line " + std::to_string(line));
    case RealParse::kMalformed:
      return Status::InvalidArgument(std::string(format) + " line " + std::to_string(line) +
                                     ": vertex " + std::to_string(vertex) +
                                     " has a coordinate that is not a number: " + Quoted(token));
  }
  return Status::Ok();
}

Status CountFaceTriangles(long long corners, std::string_view what, std::size_t limit,
                          std::size_t* num_triangles) {
  *num_triangles += corners > 3 ? static_cast<std::size_t>(corners - 2) : 1;
  if (*num_triangles > limit) return TooManyTriangles(what, limit);
  return Status::Ok();
}

}  // namespace deform::mesh_io_internal
