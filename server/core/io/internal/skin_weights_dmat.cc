// libigl DMAT weights (ASCII and binary), read into sparse per-vertex entries.
//
// The declared "cols rows" is checked against the limits and against the bytes present before
// anything is sized from it: an ASCII value needs at least two bytes (a digit and a separator), a
// binary one exactly eight.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_io_internal.h"
#include "skin_weights_io_internal.h"

namespace deform::skin_weights_io_internal {
namespace {

using mesh_io_internal::LineReader;
using mesh_io_internal::ParseInteger;
using mesh_io_internal::ParseReal;
using mesh_io_internal::Quoted;
using mesh_io_internal::RealParse;
using mesh_io_internal::SplitTokens;
using mesh_io_internal::TokenReader;

struct DmatSize {
  long long cols = 0;  // bones
  long long rows = 0;  // vertices
};

// Parses a header line "cols rows" (line `line_number`).
StatusOr<DmatSize> ParseSizeLine(std::string_view line, int line_number) {
  std::vector<std::string_view> tokens;
  SplitTokens(line, &tokens);
  DmatSize size;
  if (tokens.size() != 2 || !ParseInteger(tokens[0], &size.cols) ||
      !ParseInteger(tokens[1], &size.rows)) {
    return Status::InvalidArgument("DMAT line " + std::to_string(line_number) +
                                   ": expected the size line 'cols rows', found " + Quoted(line));
  }
  if (size.cols < 0 || size.rows < 0) {
    return Status::InvalidArgument("DMAT line " + std::to_string(line_number) + ": negative size " +
                                   Quoted(line));
  }
  return size;
}

// Refuses sizes that no weights file can mean or that exceed the limits, and sizes whose values
// cannot fit in `data_bytes` bytes of `bytes_per_value` each.
Status CheckSize(const DmatSize& size, std::size_t data_bytes, std::size_t bytes_per_value,
                 const MeshLimits& limits) {
  if (size.cols == 0 || size.rows == 0) {
    return Status::InvalidArgument("DMAT declares " + std::to_string(size.cols) + " columns and " +
                                   std::to_string(size.rows) +
                                   " rows; weights need at least one bone and one vertex");
  }
  if (static_cast<unsigned long long>(size.rows) > limits.max_vertices) {
    return mesh_io_internal::DeclaresTooMany("DMAT", static_cast<std::uint64_t>(size.rows),
                                             "rows (vertices)", limits.max_vertices);
  }
  if (size.cols > kMaxSkinBones) {
    return mesh_io_internal::DeclaresTooMany("DMAT", static_cast<std::uint64_t>(size.cols),
                                             "columns (bones)", kMaxSkinBones);
  }
  // Both factors are now below 2^32: the product cannot overflow.
  const std::uint64_t values =
      static_cast<std::uint64_t>(size.cols) * static_cast<std::uint64_t>(size.rows);
  const std::uint64_t room = data_bytes / bytes_per_value + (bytes_per_value > 1 ? 1 : 0);
  if (values > room) {
    return Status::InvalidArgument("DMAT declares " + std::to_string(size.cols) + " x " +
                                   std::to_string(size.rows) + " = " + std::to_string(values) +
                                   " values but holds only " + std::to_string(data_bytes) +
                                   " bytes of data (truncated, or a wrong size line)");
  }
  return Status::Ok();
}

std::string ValueName(long long index, const DmatSize& size) {
  return "DMAT row " + std::to_string(index % size.rows) + ", column " +
         std::to_string(index / size.rows);
}

StatusOr<SkinWeights> ParseAsciiValues(std::string_view text, int first_line, const DmatSize& size,
                                       const MeshLimits& limits) {
  DEFORM_RETURN_IF_ERROR(CheckSize(size, text.size(), 2, limits));
  const long long count = size.cols * size.rows;
  std::vector<WeightEntry> entries;
  TokenReader tokens(text, first_line);
  std::string_view token;
  for (long long index = 0; index < count; ++index) {
    if (!tokens.Next(&token)) {
      return Status::InvalidArgument("DMAT ends after " + std::to_string(index) + " of " +
                                     std::to_string(count) + " values (" +
                                     std::to_string(size.cols) + " columns x " +
                                     std::to_string(size.rows) + " rows)");
    }
    double weight = 0;
    const std::string where = ValueName(index, size) + " (line " + std::to_string(tokens.line());
    switch (ParseReal(token, &weight)) {
      case RealParse::kOk:
        break;
      case RealParse::kNonFinite:
        return Status::InvalidArgument(where + ") is not finite: " + Quoted(token));
      case RealParse::kMalformed:
        return Status::InvalidArgument(where + ") is not a number: " + Quoted(token));
    }
    DEFORM_RETURN_IF_ERROR(CheckWeight(&weight, where + ")"));
    if (weight != 0) {
      entries.push_back(
          {static_cast<int>(index % size.rows), static_cast<int>(index / size.rows), weight});
    }
  }
  if (tokens.Next(&token)) {
    return Status::InvalidArgument("DMAT line " + std::to_string(tokens.line()) +
                                   ": more values than the " + std::to_string(size.cols) + " x " +
                                   std::to_string(size.rows) + " declared, from " + Quoted(token));
  }
  return EntriesToSkinWeights(std::move(entries), static_cast<int>(size.rows),
                              static_cast<int>(size.cols));
}

double LittleEndianDouble(const char* bytes) {
  std::uint64_t bits = 0;
  for (int b = 7; b >= 0; --b) bits = (bits << 8) | static_cast<unsigned char>(bytes[b]);
  double value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

StatusOr<SkinWeights> ParseBinaryValues(std::string_view data, const DmatSize& size,
                                        const MeshLimits& limits) {
  DEFORM_RETURN_IF_ERROR(CheckSize(size, data.size(), 8, limits));
  const long long count = size.cols * size.rows;
  if (data.size() != static_cast<std::size_t>(count) * 8) {
    return Status::InvalidArgument("binary DMAT holds " + std::to_string(data.size()) +
                                   " bytes of data; " + std::to_string(size.cols) + " x " +
                                   std::to_string(size.rows) + " doubles need " +
                                   std::to_string(count * 8));
  }
  std::vector<WeightEntry> entries;
  for (long long index = 0; index < count; ++index) {
    double weight = LittleEndianDouble(data.data() + index * 8);
    DEFORM_RETURN_IF_ERROR(CheckWeight(&weight, ValueName(index, size)));
    if (weight != 0) {
      entries.push_back(
          {static_cast<int>(index % size.rows), static_cast<int>(index / size.rows), weight});
    }
  }
  return EntriesToSkinWeights(std::move(entries), static_cast<int>(size.rows),
                              static_cast<int>(size.cols));
}

}  // namespace

StatusOr<SkinWeights> ParseDmat(std::string_view bytes, const MeshLimits& limits) {
  LineReader lines(bytes);
  std::string_view line;
  if (!lines.Next(&line)) return Status::InvalidArgument("the DMAT data is empty");
  DEFORM_ASSIGN_OR_RETURN(const DmatSize first, ParseSizeLine(line, 1));
  if (first.cols != 0 || first.rows != 0) {
    return ParseAsciiValues(bytes.substr(lines.position()), 2, first, limits);
  }
  // "0 0": the binary form. Its size line ends at the first '\n'; the doubles follow at once.
  if (!lines.Next(&line)) {
    return Status::InvalidArgument("binary DMAT ('0 0') has no size line after its marker");
  }
  DEFORM_ASSIGN_OR_RETURN(const DmatSize size, ParseSizeLine(line, 2));
  if (lines.position() == bytes.size() && (bytes.empty() || bytes.back() != '\n')) {
    return Status::InvalidArgument("binary DMAT ends inside its size line");
  }
  return ParseBinaryValues(bytes.substr(lines.position()), size, limits);
}

}  // namespace deform::skin_weights_io_internal
