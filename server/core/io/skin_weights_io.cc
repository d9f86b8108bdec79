#include "core/io/skin_weights_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <new>
#include <string>
#include <utility>

#include "internal/file_bytes.h"
#include "internal/mesh_io_internal.h"
#include "internal/skin_weights_io_internal.h"

namespace deform {

namespace skin_weights_io_internal {

Status CheckWeight(double* weight, const std::string& where) {
  if (!std::isfinite(*weight)) {
    return Status::InvalidArgument(where + ": the weight is not finite");
  }
  if (*weight < 0) {
    if (*weight < -kNegativeWeightRoundOff) {
      return Status::InvalidArgument(where + ": negative weight " + std::to_string(*weight) +
                                     " (weights must be non-negative)");
    }
    *weight = 0;
  }
  return Status::Ok();
}

SkinWeights EntriesToSkinWeights(std::vector<WeightEntry> entries, int num_vertices,
                                 int num_bones) {
  std::stable_sort(entries.begin(), entries.end(),
                   [](const WeightEntry& a, const WeightEntry& b) { return a.vertex < b.vertex; });
  SkinWeights weights;
  weights.num_bones = num_bones;
  weights.offsets.assign(static_cast<std::size_t>(num_vertices) + 1, 0);
  weights.bones.reserve(entries.size());
  weights.weights.reserve(entries.size());
  for (const WeightEntry& entry : entries) {
    ++weights.offsets[static_cast<std::size_t>(entry.vertex) + 1];
    weights.bones.push_back(entry.bone);
    weights.weights.push_back(entry.weight);
  }
  for (int v = 0; v < num_vertices; ++v) weights.offsets[v + 1] += weights.offsets[v];
  return weights;
}

}  // namespace skin_weights_io_internal

namespace {

using mesh_io_internal::EqualsIgnoreCase;
using mesh_io_internal::Quoted;

}  // namespace

StatusOr<SkinWeightsFormat> SkinWeightsFormatFromName(std::string_view name) {
  std::string_view bare = name;
  if (!bare.empty() && bare.front() == '.') bare.remove_prefix(1);
  if (EqualsIgnoreCase(bare, "dmat")) return SkinWeightsFormat::kDmat;
  if (EqualsIgnoreCase(bare, "csv")) return SkinWeightsFormat::kCsv;
  return Status::InvalidArgument("unknown skinning weights format " + Quoted(name) +
                                 " (expected dmat or csv)");
}

StatusOr<SkinWeightsFormat> SkinWeightsFormatFromPath(std::string_view path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension.empty()) {
    return Status::InvalidArgument("cannot tell the skinning weights format of " + Quoted(path) +
                                   ": it has no extension (expected .dmat or .csv)");
  }
  return SkinWeightsFormatFromName(extension);
}

const char* SkinWeightsFormatName(SkinWeightsFormat format) {
  return format == SkinWeightsFormat::kDmat ? "dmat" : "csv";
}

StatusOr<SkinWeights> ReadSkinWeights(std::string_view bytes, SkinWeightsFormat format,
                                      const MeshLimits& limits) {
  try {
    if (format == SkinWeightsFormat::kDmat) {
      return skin_weights_io_internal::ParseDmat(bytes, limits);
    }
    return skin_weights_io_internal::ParseWeightsCsv(bytes, limits);
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted("out of memory while reading skinning weights");
  }
}

StatusOr<SkinWeights> ReadSkinWeightsFile(const std::string& path, const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const SkinWeightsFormat format, SkinWeightsFormatFromPath(path));
  DEFORM_ASSIGN_OR_RETURN(const std::string bytes,
                          io_internal::ReadFileBytes(path, "skinning weights file"));
  StatusOr<SkinWeights> weights = ReadSkinWeights(bytes, format, limits);
  if (!weights.ok()) return weights.status().WithContext(path);
  return weights;
}

void WidenSkinWeights(SkinWeightsFormat format, int num_vertices, int num_bones,
                      SkinWeights* weights) {
  if (format != SkinWeightsFormat::kCsv) return;
  weights->num_bones = std::max(weights->num_bones, num_bones);
  if (weights->num_vertices() < num_vertices) {
    weights->offsets.resize(static_cast<std::size_t>(num_vertices) + 1, weights->offsets.back());
  }
}

StatusOr<SkinWeights> LoadSkinWeightsFile(const std::string& path, int num_vertices, int num_bones,
                                          const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const SkinWeightsFormat format, SkinWeightsFormatFromPath(path));
  DEFORM_ASSIGN_OR_RETURN(SkinWeights weights, ReadSkinWeightsFile(path, limits));
  WidenSkinWeights(format, num_vertices, num_bones, &weights);
  StatusOr<SkinWeights> normalized = NormalizeSkinWeights(weights, num_vertices, num_bones);
  if (!normalized.ok()) return normalized.status().WithContext(path);
  return normalized;
}

}  // namespace deform
