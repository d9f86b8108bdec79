// Reading per-vertex skinning weights as rigging tools export them: libigl's DMAT (dense, ASCII or
// binary) and a sparse CSV. Both give SkinWeights (core/geometry/skin_weights.h), whose bone
// indices are the skeleton's bone order; the caller checks and cleans them against its mesh and
// skeleton with NormalizeSkinWeights (or uses LoadSkinWeightsFile, which does both).
//
// No input crashes a reader: malformed content yields INVALID_ARGUMENT naming the problem (and the
// line or value), sizes beyond MeshLimits or kMaxSkinBones RESOURCE_EXHAUSTED. Nothing is
// allocated from a declared size before the data present has been checked to hold that many
// values, so memory stays proportional to the input.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skin_weights.h"

namespace deform {

enum class SkinWeightsFormat {
  // libigl DMAT. ASCII: a line "cols rows", then cols * rows numbers separated by white space,
  // column-major (all of column 0, then column 1...). Binary: a line "0 0", a line "cols rows",
  // then exactly cols * rows little-endian IEEE doubles, column-major. Rows are vertices, columns
  // bones (in the skeleton's bone order); the counts must match the data exactly.
  kDmat,
  // Sparse text, one weight a line: "vertex,bone,weight" with 0-based indices. An optional header
  // line (first content line, not starting with a number) is skipped; blank lines and lines
  // starting with '#' are ignored; a vertex may repeat a bone (NormalizeSkinWeights sums them).
  // The counts are what the file mentions: 1 + the largest vertex index, 1 + the largest bone.
  kCsv,
};

// The largest bone count a weights file may declare or use: 65,536 (what glTF's unsigned-short
// JOINTS can address).
inline constexpr int kMaxSkinBones = 65536;

// Weights below zero by at most this much are read as 0 (solvers that compute weights, libigl's
// bounded biharmonic weights among them, leave round-off of either sign); anything more negative
// is INVALID_ARGUMENT.
inline constexpr double kNegativeWeightRoundOff = 1e-9;

// "dmat" / "csv" (case-insensitive, with or without a leading dot).
StatusOr<SkinWeightsFormat> SkinWeightsFormatFromName(std::string_view name);
// From a file name's extension.
StatusOr<SkinWeightsFormat> SkinWeightsFormatFromPath(std::string_view path);
const char* SkinWeightsFormatName(SkinWeightsFormat format);

// Parses a whole weights file held in memory. Rows (vertices) are limited by
// limits.max_vertices, bones by kMaxSkinBones. Weights are finite and non-negative (see
// kNegativeWeightRoundOff); zeros are dropped. Not normalized.
StatusOr<SkinWeights> ReadSkinWeights(std::string_view bytes, SkinWeightsFormat format,
                                      const MeshLimits& limits = {});
// Reads a file; the format comes from the extension (.dmat, .csv). NOT_FOUND if it cannot be
// opened; errors carry the path.
StatusOr<SkinWeights> ReadSkinWeightsFile(const std::string& path, const MeshLimits& limits = {});

// A CSV names only the vertices and bones it mentions: widens its counts to the mesh's and the
// skeleton's (never narrows them). A DMAT's counts are left as read (they must match).
void WidenSkinWeights(SkinWeightsFormat format, int num_vertices, int num_bones,
                      SkinWeights* weights);

// ReadSkinWeightsFile, then NormalizeSkinWeights against a mesh of `num_vertices` and a skeleton
// of `num_bones`. A CSV names only the vertices and bones it mentions, so its counts are first
// widened to the mesh's and skeleton's (never narrowed): a vertex it leaves out is then reported as
// following no bone, and bones it never names simply get no weight. A DMAT's counts must match.
StatusOr<SkinWeights> LoadSkinWeightsFile(const std::string& path, int num_vertices, int num_bones,
                                          const MeshLimits& limits = {});

}  // namespace deform
