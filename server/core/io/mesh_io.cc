// The public side of mesh reading and writing: format names, dispatch to each format's reader,
// and files.
//
// Reading goes through OpenMesh's readers into a "polygon soup" importer (mesh_soup_importer.h).
// OpenMesh's readers trust their input: on malformed data they hang, allocate without bound,
// assert, crash or silently misread (see the notes at the top of each mesh_io_<format>.cc). So
// every format is first walked there, without allocating in proportion to any declared count,
// and only input whose meaning OpenMesh reads unambiguously is handed on. Writing is done
// directly (mesh_writer.cc).
#include "core/io/mesh_io.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>

#include "internal/mesh_io_internal.h"
#include "internal/mesh_soup_importer.h"

namespace deform {
namespace {

// Each format's names and reader, in the order MeshFormatFromName tries them.
struct FormatNames {
  MeshFormat format;
  const char* name;   // as MeshFormatName
  const char* label;  // as FormatLabel
  // Checks and reads the format's bytes into the importer (mesh_io_internal.h).
  Status (*read)(std::string_view bytes, const MeshLimits& limits,
                 mesh_io_internal::SoupImporter* importer);
};

constexpr FormatNames kFormats[] = {{MeshFormat::kObj, "obj", "OBJ", &mesh_io_internal::ReadObj},
                                    {MeshFormat::kPly, "ply", "PLY", &mesh_io_internal::ReadPly},
                                    {MeshFormat::kStl, "stl", "STL", &mesh_io_internal::ReadStl},
                                    {MeshFormat::kOff, "off", "OFF", &mesh_io_internal::ReadOff}};

const FormatNames* FindFormat(MeshFormat format) {
  for (const FormatNames& names : kFormats) {
    if (names.format == format) return &names;
  }
  return nullptr;
}

}  // namespace

namespace mesh_io_internal {

const char* FormatLabel(MeshFormat format) {
  const FormatNames* names = FindFormat(format);
  return names != nullptr ? names->label : "mesh";
}

namespace {

// ReadMesh without its guard against exceptions: the format's checks and read, then the soup
// triangulated and the mesh validated.
StatusOr<TriangleMesh> ReadMeshUnguarded(std::string_view bytes, MeshFormat format,
                                         const MeshLimits& limits) {
  if (bytes.empty()) {
    return Status::InvalidArgument(std::string("the ") + FormatLabel(format) + " data is empty");
  }
  const FormatNames* names = FindFormat(format);
  if (names == nullptr) return Status::InvalidArgument("unknown mesh format");
  SoupImporter importer(limits);
  DEFORM_RETURN_IF_ERROR(names->read(bytes, limits, &importer));
  if (importer.exceeded_vertex_limit()) {
    return TooManyVertices(std::string("the ") + FormatLabel(format) + " data",
                           limits.max_vertices);
  }
  if (importer.exceeded_triangle_limit()) {
    return TooManyTriangles(std::string("the ") + FormatLabel(format) + " data",
                            limits.max_triangles);
  }
  DEFORM_ASSIGN_OR_RETURN(TriangleMesh mesh, SoupToMesh(importer.soup()));
  DEFORM_RETURN_IF_ERROR(ValidateMesh(mesh, limits));
  return mesh;
}

StatusOr<std::string> ReadWholeFile(std::ifstream* file, const std::string& path) {
  std::string bytes;
  file->seekg(0, std::ios::end);
  const std::streamoff size = file->tellg();
  file->seekg(0, std::ios::beg);
  if (size >= 0) {
    bytes.resize(static_cast<std::size_t>(size));
    file->read(bytes.data(), size);
    bytes.resize(static_cast<std::size_t>(file->gcount()));
  } else {  // not seekable (a pipe, say)
    file->clear();
    std::ostringstream contents;
    contents << file->rdbuf();
    bytes = contents.str();
  }
  if (file->bad()) return Status::Internal("reading " + path + " failed");
  return bytes;
}

}  // namespace
}  // namespace mesh_io_internal

namespace {

using mesh_io_internal::EqualsIgnoreCase;
using mesh_io_internal::FormatLabel;
using mesh_io_internal::Quoted;
using mesh_io_internal::ReadMeshUnguarded;
using mesh_io_internal::ReadWholeFile;

}  // namespace

StatusOr<MeshFormat> MeshFormatFromName(std::string_view name) {
  std::string_view bare = name;
  if (!bare.empty() && bare.front() == '.') bare.remove_prefix(1);
  for (const FormatNames& names : kFormats) {
    if (EqualsIgnoreCase(bare, names.name)) return names.format;
  }
  return Status::InvalidArgument("unknown mesh format " + Quoted(name) +
                                 " (expected obj, ply, stl or off)");
}

StatusOr<MeshFormat> MeshFormatFromPath(std::string_view path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension.empty()) {
    return Status::InvalidArgument("cannot tell the mesh format of " + Quoted(path) +
                                   ": it has no extension (expected .obj, .ply, .stl or .off)");
  }
  return MeshFormatFromName(extension);
}

const char* MeshFormatName(MeshFormat format) {
  const FormatNames* names = FindFormat(format);
  return names != nullptr ? names->name : "unknown";
}

StatusOr<TriangleMesh> ReadMesh(std::string_view bytes, MeshFormat format,
                                const MeshLimits& limits) {
  try {
    return ReadMeshUnguarded(bytes, format, limits);
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted(std::string("out of memory while reading ") +
                                     FormatLabel(format) + " data");
  } catch (const std::exception& e) {
    return Status::Internal(std::string("reading ") + FormatLabel(format) +
                            " data failed: " + e.what());
  }
}

StatusOr<TriangleMesh> ReadMeshFile(const std::string& path, const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    return Status::InvalidArgument(path + " is a directory, not a mesh file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    return Status::NotFound("cannot open mesh file " + path + ": " + std::strerror(errno));
  }
  std::string bytes;
  try {
    DEFORM_ASSIGN_OR_RETURN(bytes, ReadWholeFile(&file, path));
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted(path + " is too large to read");
  }
  StatusOr<TriangleMesh> mesh = ReadMesh(bytes, format, limits);
  if (!mesh.ok()) return mesh.status().WithContext(path);
  return mesh;
}

Status WriteMeshFile(const TriangleMesh& mesh, const std::string& path) {
  DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  return mesh_io_internal::WriteMeshAs(mesh, format, path);
}

}  // namespace deform
