// Internal to the weights readers (skin_weights_io.cc, skin_weights_dmat.cc, skin_weights_csv.cc):
// each format's parser and the sparse entries they collect. Not installed.
#pragma once

#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skin_weights.h"
#include "core/io/skin_weights_io.h"

namespace deform::skin_weights_io_internal {

// One non-zero weight as a file lists it.
struct WeightEntry {
  int vertex = 0;
  int bone = 0;
  double weight = 0;
};

// Checks one weight read from a file (finite; negative only by round-off, then read as 0) and
// names it by `where` ("DMAT row 4, column 2") when it is refused.
Status CheckWeight(double* weight, const std::string& where);

// Groups `entries` by vertex (keeping each vertex's entries in file order) into SkinWeights of
// `num_vertices` rows and `num_bones` bones. Precondition: indices lie in range.
SkinWeights EntriesToSkinWeights(std::vector<WeightEntry> entries, int num_vertices, int num_bones);

StatusOr<SkinWeights> ParseDmat(std::string_view bytes, const MeshLimits& limits);
StatusOr<SkinWeights> ParseWeightsCsv(std::string_view text, const MeshLimits& limits);

}  // namespace deform::skin_weights_io_internal
