// The size a mesh file declares before its data: what admission can know without parsing it.
//
//   OFF  the counts line after the "OFF" keyword (vertices, faces);
//   PLY  the header's "element vertex N" and "element face N" (ASCII and binary PLY alike);
//   STL  binary STL's triangle count (bytes 80-83) when the size matches it exactly (84 + 50 per
//        triangle; vertices at most 3 per triangle before welding); ASCII STL: its "facet" lines;
//   OBJ  its "v" and "f" lines, counted (OBJ declares nothing; a scan allocates nothing).
// Faces with more than three corners are counted as one (a polygon gives n - 2 triangles: the
// estimate errs low there, which the parsed mesh's check corrects before the build).
//
// Never allocates in proportion to the input and never fails: malformed or missing headers give
// std::nullopt (the parser then reports the problem), so it is safe on any bytes.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

#include "core/io/mesh_io.h"

namespace deform {

struct DeclaredMeshSize {
  std::size_t vertices = 0;
  std::size_t faces = 0;
};

std::optional<DeclaredMeshSize> ReadDeclaredMeshSize(std::string_view bytes, MeshFormat format);

}  // namespace deform
