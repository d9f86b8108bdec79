// Reading STL data: the checks that come before OpenMesh's STL reader, and the read.
//
// OpenMesh's binary STL reader loops over the declared triangle count (up to 2^32) however short
// the input, and it welds vertices through a std::map whose comparison breaks down on NaN (a
// NaN corner is merged with an arbitrary vertex). The ASCII reader starts a facet at any line
// containing "outer" and reads the next three lines as vertices whatever they hold (a blank or
// malformed line repeats the previous vertex). It welds equal positions, like the binary
// reader, and drops facets whose corners weld together. So the data is checked here first.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_io_internal.h"
#include "mesh_soup_importer.h"

namespace deform::mesh_io_internal {
namespace {

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

}  // namespace

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

}  // namespace deform::mesh_io_internal
