// Sparse CSV weights: "vertex,bone,weight" lines, an optional header, blank lines and '#' comments.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/text.h"
#include "mesh_io_internal.h"
#include "skin_weights_io_internal.h"

namespace deform::skin_weights_io_internal {
namespace {

using mesh_io_internal::LineReader;
using mesh_io_internal::ParseInteger;
using mesh_io_internal::ParseReal;
using mesh_io_internal::Quoted;
using mesh_io_internal::RealParse;

// The comma-separated fields of `line`, trimmed.
std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
        Trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool StartsLikeANumber(std::string_view field) {
  if (!field.empty() && (field.front() == '+' || field.front() == '-')) field.remove_prefix(1);
  return !field.empty() && ((field.front() >= '0' && field.front() <= '9') || field.front() == '.');
}

// Parses an index field naming a `noun` ("vertex", "bone") that must stay below `limit`.
StatusOr<int> ParseIndexField(std::string_view field, const char* noun, std::size_t limit,
                              const std::string& where) {
  long long value = 0;
  if (!ParseInteger(field, &value)) {
    return Status::InvalidArgument(where + ": the " + noun +
                                   " index is not an integer: " + Quoted(field));
  }
  if (value < 0) {
    return Status::InvalidArgument(where + ": negative " + noun + " index " +
                                   std::to_string(value));
  }
  if (static_cast<unsigned long long>(value) >= limit) {
    return Status::ResourceExhausted(where + ": " + noun + " index " + std::to_string(value) +
                                     " is beyond the limit of " + std::to_string(limit) + " " +
                                     noun + (std::string_view(noun) == "vertex" ? "es" : "s"));
  }
  return static_cast<int>(value);
}

}  // namespace

StatusOr<SkinWeights> ParseWeightsCsv(std::string_view text, const MeshLimits& limits) {
  LineReader lines(text);
  std::string_view line;
  std::vector<WeightEntry> entries;
  int num_vertices = 0;
  int num_bones = 0;
  bool seen_content = false;
  while (lines.Next(&line)) {
    const std::string_view content = Trim(line);
    if (content.empty() || content.front() == '#') continue;
    const std::string where = "CSV line " + std::to_string(lines.line_number());
    const std::vector<std::string_view> fields = SplitFields(content);
    if (!seen_content && !StartsLikeANumber(fields.front())) {
      seen_content = true;  // a header line, e.g. "vertex,bone,weight"
      continue;
    }
    seen_content = true;
    if (fields.size() != 3) {
      return Status::InvalidArgument(where + ": expected 'vertex,bone,weight', found " +
                                     std::to_string(fields.size()) + " field(s) in " +
                                     Quoted(content));
    }
    WeightEntry entry;
    DEFORM_ASSIGN_OR_RETURN(entry.vertex,
                            ParseIndexField(fields[0], "vertex", limits.max_vertices, where));
    DEFORM_ASSIGN_OR_RETURN(entry.bone, ParseIndexField(fields[1], "bone", kMaxSkinBones, where));
    switch (ParseReal(fields[2], &entry.weight)) {
      case RealParse::kOk:
        break;
      case RealParse::kNonFinite:
        return Status::InvalidArgument(where + ": the weight is not finite: " + Quoted(fields[2]));
      case RealParse::kMalformed:
        return Status::InvalidArgument(where +
                                       ": the weight is not a number: " + Quoted(fields[2]));
    }
    DEFORM_RETURN_IF_ERROR(CheckWeight(&entry.weight, where));
    num_vertices = std::max(num_vertices, entry.vertex + 1);
    num_bones = std::max(num_bones, entry.bone + 1);
    if (entry.weight != 0) entries.push_back(entry);
  }
  if (num_vertices == 0) return Status::InvalidArgument("the CSV holds no weights");
  return EntriesToSkinWeights(std::move(entries), num_vertices, num_bones);
}

}  // namespace deform::skin_weights_io_internal
