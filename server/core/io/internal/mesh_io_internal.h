// Internal to the mesh reader and writer (mesh_io*.cc, mesh_soup_importer.cc, mesh_writer.cc):
// text and number helpers, the error messages the format checks share, and each format's read
// entry point. Not installed; nothing outside server/core includes it.
//
// The text helpers read input the way OpenMesh's readers do (`std::istream >>` for numbers,
// std::getline for lines), so that the checks see exactly the tokens OpenMesh will read.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/base/text.h"
#include "core/geometry/mesh.h"
#include "core/io/mesh_io.h"

namespace deform::mesh_io_internal {

class SoupImporter;  // mesh_soup_importer.h

// ---------------------------------------------------------------------------------------------
// Text helpers (mesh_io_text.cc)

// IsSpace and Trim are core/base/text.h's.
bool EqualsIgnoreCase(std::string_view a, std::string_view b);
bool StartsWithIgnoreCase(std::string_view text, std::string_view prefix);

// A token quoted for an error message: shortened, with unprintable bytes replaced.
std::string Quoted(std::string_view token);

// The whitespace-separated tokens of `line`, replacing `*tokens`.
void SplitTokens(std::string_view line, std::vector<std::string_view>* tokens);

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
// Numbers as the OpenMesh text readers (std::istream >>) accept them (mesh_io_text.cc)

// The whole token as a decimal integer that fits a long long; one leading '+' is skipped.
bool ParseInteger(std::string_view token, long long* value);

enum class RealParse { kOk, kNonFinite, kMalformed };

// Parses a decimal number. Magnitudes beyond float range count as non-finite: OpenMesh keeps
// positions as floats, and its text readers fail on such values.
RealParse ParseReal(std::string_view token, double* value);

// Appends the shortest text that reads back to the same value.
void AppendReal(std::string* out, double value);
void AppendInteger(std::string* out, long long value);

// ---------------------------------------------------------------------------------------------
// Format names (mesh_io.cc)

// "OBJ", "PLY", "STL" or "OFF", for messages.
const char* FormatLabel(MeshFormat format);

// ---------------------------------------------------------------------------------------------
// What the format checks report (mesh_io_checks.cc)

// RESOURCE_EXHAUSTED: "<header> declares <count> <noun>; the limit is <limit>".
Status DeclaresTooMany(std::string_view header, std::uint64_t count, std::string_view noun,
                       std::size_t limit);
// RESOURCE_EXHAUSTED: "<what> has more than <limit> vertices (the limit)"; likewise triangles.
Status TooManyVertices(std::string_view what, std::size_t limit);
Status TooManyTriangles(std::string_view what, std::size_t limit);
// INVALID_ARGUMENT: "vertex <vertex> has a non-finite coordinate (<token>, <where>)".
Status NonFiniteCoordinate(std::size_t vertex, std::string_view token, std::string_view where);

// Parses coordinate `token` of vertex `vertex`, read on line `line` of `format`'s text ("OBJ").
// INVALID_ARGUMENT naming the vertex when it is non-finite (NonFiniteCoordinate) or not a number
// ("<format> line <line>: vertex <vertex> has a coordinate that is not a number: <token>").
Status ParseVertexCoordinate(std::string_view token, std::size_t vertex, std::string_view format,
                             int line, double* value);

// Adds the triangles a face of `corners` corners fans into to `*num_triangles` (a face of fewer
// than four corners counts as one); TooManyTriangles(what, limit) once the total passes `limit`.
Status CountFaceTriangles(long long corners, std::string_view what, std::size_t limit,
                          std::size_t* num_triangles);

// ---------------------------------------------------------------------------------------------
// Reading one format into `importer`, after checking the input (mesh_io_<format>.cc)

Status ReadObj(std::string_view text, const MeshLimits& limits, SoupImporter* importer);
Status ReadPly(std::string_view bytes, const MeshLimits& limits, SoupImporter* importer);
Status ReadStl(std::string_view bytes, const MeshLimits& limits, SoupImporter* importer);
Status ReadOff(std::string_view text, const MeshLimits& limits, SoupImporter* importer);

// ---------------------------------------------------------------------------------------------
// Writing (mesh_writer.cc)

// Writes `mesh` to `path` in `format`. INVALID_ARGUMENT (with "cannot write <path>") for
// out-of-range indices or non-finite coordinates; NOT_FOUND when the folder does not exist.
Status WriteMeshAs(const TriangleMesh& mesh, MeshFormat format, const std::string& path);

}  // namespace deform::mesh_io_internal
