// The OpenMesh side of reading: a "polygon soup" importer that records raw positions and face
// index lists (a halfedge mesh would silently drop non-manifold faces before validation could see
// them), and the driver that runs one of OpenMesh's readers into it.
//
// OpenMesh's readers trust their input, so ReadWithOpenMesh is only ever handed data that a
// format's check (mesh_io_<format>.cc) has walked and accepted.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

// OpenMesh's MeshIO.hh must come before any mesh kernel header, or its readers do not register.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/io/mesh_io.h"

namespace deform::mesh_io_internal {

// Raw positions and faces exactly as a reader delivered them.
struct PolygonSoup {
  std::vector<double> coordinates;             // x, y, z per vertex
  std::vector<int> corners;                    // the vertex indices of all faces, face by face
  std::vector<std::size_t> face_starts = {0};  // face f is corners[face_starts[f], [f + 1])

  std::size_t num_vertices() const { return coordinates.size() / 3; }
  std::size_t num_faces() const { return face_starts.size() - 1; }
};

// Records what an OpenMesh reader delivers, with no topology and no checks, so that validation
// sees every face. Stops storing (and flags it) once `limits` are exceeded, so that memory stays
// bounded whatever a reader does. Attributes (normals, colours, texture coordinates) are ignored.
class SoupImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VertexHandle = OpenMesh::VertexHandle;
  using FaceHandle = OpenMesh::FaceHandle;
  using HalfedgeHandle = OpenMesh::HalfedgeHandle;
  using EdgeHandle = OpenMesh::EdgeHandle;
  using Vec2f = OpenMesh::Vec2f;
  using Vec3f = OpenMesh::Vec3f;
  using Vec3d = OpenMesh::Vec3d;
  using Vec3uc = OpenMesh::Vec3uc;
  using Vec4uc = OpenMesh::Vec4uc;
  using Vec4f = OpenMesh::Vec4f;
  using StatusInfo = OpenMesh::Attributes::StatusInfo;

  explicit SoupImporter(const MeshLimits& limits) : limits_(limits) {}

  const PolygonSoup& soup() const { return soup_; }
  bool exceeded_vertex_limit() const { return exceeded_vertex_limit_; }
  bool exceeded_triangle_limit() const { return exceeded_triangle_limit_; }

  VertexHandle add_vertex(const Vec3f& p) override { return AddVertex(p[0], p[1], p[2]); }
  VertexHandle add_vertex(const Vec3d& p) override { return AddVertex(p[0], p[1], p[2]); }
  VertexHandle add_vertex() override { return AddVertex(0.0, 0.0, 0.0); }
  void set_point(VertexHandle vh, const Vec3f& p) override {
    if (vh.idx() < 0 || static_cast<std::size_t>(vh.idx()) >= soup_.num_vertices()) return;
    double* xyz = &soup_.coordinates[3 * static_cast<std::size_t>(vh.idx())];
    xyz[0] = p[0];
    xyz[1] = p[1];
    xyz[2] = p[2];
  }
  FaceHandle add_face(const VHandles& handles) override;

  void reserve(unsigned int num_vertices, unsigned int, unsigned int num_faces) override {
    soup_.coordinates.reserve(3 * std::min<std::size_t>(num_vertices, limits_.max_vertices));
    soup_.face_starts.reserve(1 + std::min<std::size_t>(num_faces, limits_.max_triangles));
  }
  size_t n_vertices() const override { return num_vertices_seen_; }
  size_t n_faces() const override { return num_faces_seen_; }
  size_t n_edges() const override { return 0; }

  // Everything below is deliberately ignored.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_status(EdgeHandle, const StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

 private:
  VertexHandle AddVertex(double x, double y, double z);

  MeshLimits limits_;
  PolygonSoup soup_;
  std::size_t num_vertices_seen_ = 0;
  std::size_t num_faces_seen_ = 0;
  std::size_t num_triangles_seen_ = 0;
  bool exceeded_vertex_limit_ = false;
  bool exceeded_triangle_limit_ = false;
};

// Fan-triangulates the soup. Faces with fewer than three corners and out-of-range indices are
// reported with the file's (0-based) face number.
StatusOr<TriangleMesh> SoupToMesh(const PolygonSoup& soup);

// Runs OpenMesh's reader for `format` over `bytes` into `importer`, one read at a time (the
// readers are global singletons with per-read state). INVALID_ARGUMENT, with what OpenMesh printed,
// when the reader fails. Precondition: `bytes` passed the format's checks. `binary` selects binary
// STL.
Status ReadWithOpenMesh(std::string_view bytes, MeshFormat format, bool binary,
                        SoupImporter* importer);

// INVALID_ARGUMENT unless OpenMesh delivered exactly the vertex and face counts the check found.
Status CheckImportedCounts(const SoupImporter& importer, MeshFormat format,
                           std::size_t expected_vertices, std::size_t expected_faces);

}  // namespace deform::mesh_io_internal
