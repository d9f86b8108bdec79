// Reading and writing triangle meshes through OpenMesh.
//
// Supported: OBJ, PLY (ASCII and binary), STL (ASCII and binary; duplicate vertices welded),
// OFF. Polygons are fan-triangulated. No input crashes the reader: unreadable, truncated or
// malformed content yields INVALID_ARGUMENT naming the problem.
//
// What the readers validate: first what parsing needs (syntax, numbers, indices, and declared
// counts against the limits before anything is allocated for them), then the whole mesh with
// ValidateMesh(limits) before it is returned, so a returned mesh is always usable and a bad file
// is reported as the file's problem. DeformationModel::Build validates its input again for callers
// that make meshes in code; callers of these readers need not validate.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/geometry/mesh.h"

namespace deform {

enum class MeshFormat { kObj, kPly, kStl, kOff };

// "obj" / "ply" / "stl" / "off" (case-insensitive, with or without a leading dot).
StatusOr<MeshFormat> MeshFormatFromName(std::string_view name);
// From a file name's extension.
StatusOr<MeshFormat> MeshFormatFromPath(std::string_view path);
const char* MeshFormatName(MeshFormat format);

// Parses a whole mesh file held in memory (e.g. received over the network).
StatusOr<TriangleMesh> ReadMesh(std::string_view bytes, MeshFormat format,
                                const MeshLimits& limits = {});
// Reads a file; the format comes from the extension. NOT_FOUND if the file cannot be opened.
StatusOr<TriangleMesh> ReadMeshFile(const std::string& path, const MeshLimits& limits = {});

// Writes a mesh; the format comes from the extension (.obj .ply .off .stl; PLY and STL binary).
// Written directly rather than through OpenMesh's halfedge writers, so any triangle soup can be
// written; text formats keep doubles exactly, PLY stores doubles, STL floats (and loses unused
// vertices). INVALID_ARGUMENT for out-of-range indices or non-finite coordinates, NOT_FOUND if the
// folder does not exist.
Status WriteMeshFile(const TriangleMesh& mesh, const std::string& path);

}  // namespace deform
