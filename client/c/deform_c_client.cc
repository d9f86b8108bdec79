// The C API's client and mesh functions (deform_c.h) over deform::client::DeformClient.
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "c_api_errors.h"
#include "c_api_handles.h"
#include "deform_c.h"

namespace deform::c_api {
namespace {

std::string Text(const char* text) { return text != nullptr ? text : ""; }
bool Set(const char* text) { return text != nullptr && text[0] != '\0'; }

// Builds the C++ options from the C struct (files read here).
deform_status MakeClientOptions(const deform_connect_options& in, client::ClientOptions* out) {
  if (Set(in.ca_file) || Set(in.cert_file) || Set(in.key_file)) {
    const grpc::Status read = client::LoadClientTlsFiles(Text(in.ca_file), Text(in.cert_file),
                                                         Text(in.key_file), &out->tls);
    if (!read.ok()) return FromGrpc(read, "deform_connect");
  }
  if (in.tls != 0 || Set(in.ca_pem) || Set(in.cert_pem) || Set(in.key_pem)) out->tls.enabled = true;
  if (Set(in.ca_pem)) out->tls.ca_pem = in.ca_pem;
  if (Set(in.cert_pem)) out->tls.cert_pem = in.cert_pem;
  if (Set(in.key_pem)) out->tls.key_pem = in.key_pem;
  if (out->tls.cert_pem.empty() != out->tls.key_pem.empty()) {
    return Fail(DEFORM_INVALID_ARGUMENT,
                "deform_connect: a client certificate needs its key and a key its certificate");
  }
  out->tls.server_name = Text(in.server_name);
  out->token = Text(in.token);
  if (in.unary_deadline_ms < 0) {
    return Fail(DEFORM_INVALID_ARGUMENT, "deform_connect: unary_deadline_ms is negative");
  }
  if (in.unary_deadline_ms > 0) out->unary_deadline_ms = in.unary_deadline_ms;
  return Succeed();
}

deform_status MakeMesh(const std::shared_ptr<client::DeformClient>& client,
                       const v1::MeshSummary& summary, deform_mesh** out) {
  auto mesh = std::make_unique<deform_mesh>();
  mesh->client = client;
  mesh->summary = summary;
  *out = mesh.release();
  return Succeed();
}

const v1::JointInfo* FindJoint(const deform_mesh* mesh, std::uint32_t joint, const char* function,
                               deform_status* status) {
  if (joint >= static_cast<std::uint32_t>(mesh->summary.joints_size())) {
    *status =
        Fail(DEFORM_OUT_OF_RANGE, std::string(function) + ": joint " + std::to_string(joint) +
                                      " of a skeleton with " +
                                      std::to_string(mesh->summary.joints_size()) + " joints");
    return nullptr;
  }
  return &mesh->summary.joints(static_cast<int>(joint));
}

// Fetches the rest positions and triangles into the handle once.
deform_status LoadGeometryLocked(deform_mesh* mesh) {
  if (mesh->geometry_loaded) return Succeed();
  v1::GetMeshInfoResponse info;
  const grpc::Status status =
      mesh->client->GetMeshInfo(mesh->summary.mesh_id(), /*include_geometry=*/true, &info);
  if (!status.ok()) return FromGrpc(status, "deform_mesh_rest_geometry");
  const std::size_t floats = 3 * static_cast<std::size_t>(mesh->summary.vertex_count());
  const std::size_t indices = 3 * static_cast<std::size_t>(mesh->summary.triangle_count());
  if (info.rest_positions().size() != 4 * floats || info.triangles().size() != 4 * indices) {
    return Fail(DEFORM_INTERNAL,
                "deform_mesh_rest_geometry: the server's geometry does not match the mesh's "
                "counts (" +
                    std::to_string(info.rest_positions().size()) + " position bytes, " +
                    std::to_string(info.triangles().size()) + " triangle bytes)");
  }
  const int surfaces = mesh->summary.bone_surfaces_size();
  if (info.bone_surfaces_size() != surfaces) {
    return Fail(DEFORM_INTERNAL, "deform_mesh_rest_geometry: the server sent " +
                                     std::to_string(info.bone_surfaces_size()) +
                                     " bone surfaces' geometry for " + std::to_string(surfaces) +
                                     " bone surfaces");
  }
  std::vector<deform_mesh::BoneSurfaceGeometry> bones(static_cast<std::size_t>(surfaces));
  for (int s = 0; s < surfaces; ++s) {
    const v1::BoneSurfaceInfo& summary = mesh->summary.bone_surfaces(s);
    const v1::BoneSurfaceGeometry& geometry = info.bone_surfaces(s);
    const std::size_t bone_floats = 3 * static_cast<std::size_t>(summary.vertex_count());
    const std::size_t bone_indices = 3 * static_cast<std::size_t>(summary.triangle_count());
    if (geometry.rest_positions().size() != 4 * bone_floats ||
        geometry.triangles().size() != 4 * bone_indices) {
      return Fail(DEFORM_INTERNAL, "deform_mesh_rest_geometry: bone surface " + std::to_string(s) +
                                       "'s geometry does not match its counts");
    }
    bones[static_cast<std::size_t>(s)].rest_positions.resize(bone_floats);
    std::memcpy(bones[static_cast<std::size_t>(s)].rest_positions.data(),
                geometry.rest_positions().data(), 4 * bone_floats);
    bones[static_cast<std::size_t>(s)].triangles.resize(bone_indices);
    std::memcpy(bones[static_cast<std::size_t>(s)].triangles.data(), geometry.triangles().data(),
                4 * bone_indices);
  }
  // Little-endian on the wire and on every host this library builds for.
  mesh->rest_positions.resize(floats);
  std::memcpy(mesh->rest_positions.data(), info.rest_positions().data(), 4 * floats);
  mesh->triangles.resize(indices);
  std::memcpy(mesh->triangles.data(), info.triangles().data(), 4 * indices);
  mesh->bone_surfaces = std::move(bones);
  mesh->geometry_loaded = true;
  return Succeed();
}

const v1::BoneSurfaceInfo* FindBoneSurface(const deform_mesh* mesh, std::uint32_t surface,
                                           const char* function, deform_status* status) {
  if (surface >= static_cast<std::uint32_t>(mesh->summary.bone_surfaces_size())) {
    *status = Fail(DEFORM_OUT_OF_RANGE, std::string(function) + ": bone surface " +
                                            std::to_string(surface) + " of a mesh with " +
                                            std::to_string(mesh->summary.bone_surfaces_size()));
    return nullptr;
  }
  return &mesh->summary.bone_surfaces(static_cast<int>(surface));
}

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the wire format is little-endian");
// The C# ConnectOptions of client/csharp/Deform.cs (P/Invoke, LayoutKind.Sequential) relies on this
// layout (the ctest csharp_binding compares every struct's layout with the C compiler's).
static_assert(sizeof(deform_connect_options) == 88, "deform_connect_options' layout changed");

}  // namespace
}  // namespace deform::c_api

using deform::c_api::Fail;
using deform::c_api::FromGrpc;
using deform::c_api::Get;
using deform::c_api::Guarded;
using deform::c_api::Succeed;

extern "C" {

deform_status deform_connect(const deform_connect_options* options, deform_client** out) {
  return Guarded(__func__, {{options, "options"}, {out, "out"}}, [&] {
    if (options->target == nullptr || options->target[0] == '\0') {
      return Fail(DEFORM_INVALID_ARGUMENT, "deform_connect: options.target is not set");
    }
    deform::client::ClientOptions client_options;
    const deform_status status = deform::c_api::MakeClientOptions(*options, &client_options);
    if (status != DEFORM_OK) return status;
    auto handle = std::make_unique<deform_client>();
    handle->client =
        std::make_shared<deform::client::DeformClient>(options->target, client_options);
    if (options->connect_timeout_ms > 0 &&
        !handle->client->WaitForReady(options->connect_timeout_ms)) {
      return Fail(DEFORM_UNAVAILABLE, "deform_connect: no connection to '" +
                                          std::string(options->target) + "' within " +
                                          std::to_string(options->connect_timeout_ms) + " ms");
    }
    *out = handle.release();
    return Succeed();
  });
}

void deform_client_free(deform_client* client) { delete client; }

deform_status deform_load_phantom(deform_client* client, int vertices, const char* name,
                                  deform_mesh** out) {
  return Guarded(__func__, {{client, "client"}, {out, "out"}}, [&] {
    if (vertices < 0) return Fail(DEFORM_INVALID_ARGUMENT, "deform_load_phantom: vertices < 0");
    deform::v1::MeshSummary summary;
    const grpc::Status loaded = client->client->LoadPhantom(
        vertices, deform::v1::MethodOptions(), &summary, {}, name != nullptr ? name : "phantom");
    if (!loaded.ok()) return FromGrpc(loaded, "deform_load_phantom");
    return deform::c_api::MakeMesh(client->client, summary, out);
  });
}

deform_status deform_load_files(deform_client* client, const char* mesh_path,
                                const char* skeleton_path, const char* weights_path,
                                deform_mesh** out) {
  return Guarded(__func__, {{client, "client"}, {mesh_path, "mesh_path"}, {out, "out"}}, [&] {
    deform::v1::MeshSummary summary;
    const grpc::Status loaded = client->client->LoadMeshFiles(
        mesh_path, deform::c_api::Text(skeleton_path), deform::v1::MethodOptions(), &summary, {},
        deform::c_api::Text(weights_path));
    if (!loaded.ok()) return FromGrpc(loaded, "deform_load_files");
    return deform::c_api::MakeMesh(client->client, summary, out);
  });
}

deform_status deform_load_files_with_bones(deform_client* client, const char* mesh_path,
                                           const char* skeleton_path, const char* weights_path,
                                           const char* const* bone_surfaces,
                                           size_t bone_surface_count, deform_mesh** out) {
  const char* const fn = __func__;
  return Guarded(fn, {{client, "client"}, {mesh_path, "mesh_path"}, {out, "out"}}, [&] {
    if (bone_surface_count > 0 && bone_surfaces == nullptr) {
      return Fail(DEFORM_INVALID_ARGUMENT, std::string(fn) + ": bone_surfaces is NULL with " +
                                               std::to_string(bone_surface_count) + " specs");
    }
    std::vector<std::string> specs;
    for (std::size_t i = 0; i < bone_surface_count; ++i) {
      if (bone_surfaces[i] == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT,
                    std::string(fn) + ": bone_surfaces[" + std::to_string(i) + "] is NULL");
      }
      specs.emplace_back(bone_surfaces[i]);
    }
    deform::v1::MeshSummary summary;
    const grpc::Status loaded = client->client->LoadMeshFiles(
        mesh_path, deform::c_api::Text(skeleton_path), deform::v1::MethodOptions(), &summary, {},
        deform::c_api::Text(weights_path), specs);
    if (!loaded.ok()) return FromGrpc(loaded, fn);
    return deform::c_api::MakeMesh(client->client, summary, out);
  });
}

deform_status deform_mesh_open(deform_client* client, const char* mesh_id, deform_mesh** out) {
  return Guarded(__func__, {{client, "client"}, {mesh_id, "mesh_id"}, {out, "out"}}, [&] {
    deform::v1::GetMeshInfoResponse info;
    const grpc::Status found = client->client->GetMeshInfo(mesh_id, false, &info);
    if (!found.ok()) return FromGrpc(found, "deform_mesh_open");
    return deform::c_api::MakeMesh(client->client, info.summary(), out);
  });
}

void deform_mesh_free(deform_mesh* mesh) { delete mesh; }

deform_status deform_mesh_id(const deform_mesh* mesh, const char** id) {
  return Get(__func__, mesh, "mesh", id, "id",
             [](const deform_mesh& m) { return m.summary.mesh_id().c_str(); });
}

deform_status deform_mesh_name(const deform_mesh* mesh, const char** name) {
  return Get(__func__, mesh, "mesh", name, "name",
             [](const deform_mesh& m) { return m.summary.name().c_str(); });
}

deform_status deform_mesh_vertex_count(const deform_mesh* mesh, uint32_t* count) {
  return Get(__func__, mesh, "mesh", count, "count",
             [](const deform_mesh& m) { return m.summary.vertex_count(); });
}

deform_status deform_mesh_triangle_count(const deform_mesh* mesh, uint32_t* count) {
  return Get(__func__, mesh, "mesh", count, "count",
             [](const deform_mesh& m) { return m.summary.triangle_count(); });
}

deform_status deform_mesh_rest_geometry(deform_mesh* mesh, float* positions, size_t capacity_floats,
                                        uint32_t* triangles, size_t capacity_indices) {
  return Guarded(__func__, {{mesh, "mesh"}}, [&] {
    const std::size_t floats = 3 * static_cast<std::size_t>(mesh->summary.vertex_count());
    const std::size_t indices = 3 * static_cast<std::size_t>(mesh->summary.triangle_count());
    if (positions != nullptr && capacity_floats < floats) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_mesh_rest_geometry: positions hold " + std::to_string(capacity_floats) +
                      " floats; the mesh needs " + std::to_string(floats) + " (3 x " +
                      std::to_string(mesh->summary.vertex_count()) + " vertices)");
    }
    if (triangles != nullptr && capacity_indices < indices) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_mesh_rest_geometry: triangles hold " + std::to_string(capacity_indices) +
                      " indices; the mesh needs " + std::to_string(indices) + " (3 x " +
                      std::to_string(mesh->summary.triangle_count()) + " triangles)");
    }
    std::lock_guard<std::mutex> lock(mesh->geometry_mutex);
    const deform_status status = deform::c_api::LoadGeometryLocked(mesh);
    if (status != DEFORM_OK) return status;
    if (positions != nullptr) {
      std::memcpy(positions, mesh->rest_positions.data(), sizeof(float) * floats);
    }
    if (triangles != nullptr) {
      std::memcpy(triangles, mesh->triangles.data(), sizeof(std::uint32_t) * indices);
    }
    return Succeed();
  });
}

deform_status deform_mesh_joint_count(const deform_mesh* mesh, uint32_t* count) {
  return Get(__func__, mesh, "mesh", count, "count",
             [](const deform_mesh& m) { return static_cast<uint32_t>(m.summary.joints_size()); });
}

deform_status deform_mesh_joint(const deform_mesh* mesh, uint32_t joint, deform_joint_info* info) {
  const char* const fn = __func__;
  return Guarded(fn, {{mesh, "mesh"}, {info, "info"}}, [&] {
    deform_status status;
    const deform::v1::JointInfo* found = deform::c_api::FindJoint(mesh, joint, fn, &status);
    if (found == nullptr) return status;
    info->name = found->name().c_str();
    for (int a = 0; a < 3; ++a) {
      info->rest_position[a] =
          a < found->rest_position_size() ? static_cast<float>(found->rest_position(a)) : 0.0f;
    }
    info->dof_count = static_cast<uint32_t>(found->dofs_size());
    info->has_region = found->has_region() ? 1 : 0;
    return Succeed();
  });
}

deform_status deform_mesh_joint_dof(const deform_mesh* mesh, uint32_t joint, uint32_t dof,
                                    deform_dof_info* info) {
  const char* const fn = __func__;
  return Guarded(fn, {{mesh, "mesh"}, {info, "info"}}, [&] {
    deform_status status;
    const deform::v1::JointInfo* found = deform::c_api::FindJoint(mesh, joint, fn, &status);
    if (found == nullptr) return status;
    if (dof >= static_cast<uint32_t>(found->dofs_size())) {
      return Fail(DEFORM_OUT_OF_RANGE, "deform_mesh_joint_dof: degree of freedom " +
                                           std::to_string(dof) + " of joint '" + found->name() +
                                           "', which has " + std::to_string(found->dofs_size()));
    }
    const deform::v1::DegreeOfFreedom& d = found->dofs(static_cast<int>(dof));
    info->name = d.name().c_str();
    for (int a = 0; a < 3; ++a) {
      info->axis[a] = a < d.axis_size() ? static_cast<float>(d.axis(a)) : 0.0f;
    }
    info->min_degrees = static_cast<float>(d.min_degrees());
    info->max_degrees = static_cast<float>(d.max_degrees());
    return Succeed();
  });
}

deform_status deform_mesh_bone_surface_count(const deform_mesh* mesh, uint32_t* count) {
  return Get(__func__, mesh, "mesh", count, "count", [](const deform_mesh& m) {
    return static_cast<uint32_t>(m.summary.bone_surfaces_size());
  });
}

deform_status deform_mesh_bone_surface(const deform_mesh* mesh, uint32_t surface,
                                       deform_bone_surface_info* info) {
  const char* const fn = __func__;
  return Guarded(fn, {{mesh, "mesh"}, {info, "info"}}, [&] {
    deform_status status;
    const deform::v1::BoneSurfaceInfo* found =
        deform::c_api::FindBoneSurface(mesh, surface, fn, &status);
    if (found == nullptr) return status;
    info->name = found->name().c_str();
    info->bone = found->bone();
    info->blend_bone = found->blend_bone();
    info->blend = static_cast<float>(found->blend());
    info->vertex_count = found->vertex_count();
    info->triangle_count = found->triangle_count();
    return Succeed();
  });
}

deform_status deform_mesh_bone_surface_geometry(deform_mesh* mesh, uint32_t surface,
                                                float* positions, size_t capacity_floats,
                                                uint32_t* triangles, size_t capacity_indices) {
  const char* const fn = __func__;
  return Guarded(fn, {{mesh, "mesh"}}, [&] {
    deform_status status;
    const deform::v1::BoneSurfaceInfo* found =
        deform::c_api::FindBoneSurface(mesh, surface, fn, &status);
    if (found == nullptr) return status;
    const std::size_t floats = 3 * static_cast<std::size_t>(found->vertex_count());
    const std::size_t indices = 3 * static_cast<std::size_t>(found->triangle_count());
    if ((positions != nullptr && capacity_floats < floats) ||
        (triangles != nullptr && capacity_indices < indices)) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  std::string(fn) + ": bone surface " + std::to_string(surface) + " needs " +
                      std::to_string(floats) + " floats and " + std::to_string(indices) +
                      " indices; given room for " + std::to_string(capacity_floats) + " and " +
                      std::to_string(capacity_indices));
    }
    std::lock_guard<std::mutex> lock(mesh->geometry_mutex);
    status = deform::c_api::LoadGeometryLocked(mesh);
    if (status != DEFORM_OK) return status;
    const deform_mesh::BoneSurfaceGeometry& geometry = mesh->bone_surfaces[surface];
    if (positions != nullptr) {
      std::memcpy(positions, geometry.rest_positions.data(), sizeof(float) * floats);
    }
    if (triangles != nullptr) {
      std::memcpy(triangles, geometry.triangles.data(), sizeof(std::uint32_t) * indices);
    }
    return Succeed();
  });
}

deform_status deform_list_meshes(deform_client* client, char* buffer, size_t capacity,
                                 size_t* needed, size_t* count) {
  return Guarded(__func__, {{client, "client"}}, [&] {
    if (buffer == nullptr && capacity > 0) {
      return Fail(DEFORM_INVALID_ARGUMENT, "deform_list_meshes: buffer is NULL, capacity > 0");
    }
    std::vector<deform::v1::MeshSummary> meshes;
    const grpc::Status listed = client->client->ListMeshes(&meshes);
    if (!listed.ok()) return FromGrpc(listed, "deform_list_meshes");
    std::string text;
    for (const deform::v1::MeshSummary& mesh : meshes) text += mesh.mesh_id() + "\n";
    if (needed != nullptr) *needed = text.size() + 1;
    if (count != nullptr) *count = meshes.size();
    if (capacity < text.size() + 1) {
      return Fail(DEFORM_INVALID_ARGUMENT,
                  "deform_list_meshes: the buffer holds " + std::to_string(capacity) +
                      " bytes; the list needs " + std::to_string(text.size() + 1));
    }
    std::memcpy(buffer, text.c_str(), text.size() + 1);
    return Succeed();
  });
}

deform_status deform_unload_mesh(deform_client* client, const char* mesh_id) {
  return Guarded(__func__, {{client, "client"}, {mesh_id, "mesh_id"}}, [&] {
    return FromGrpc(client->client->UnloadMesh(mesh_id), "deform_unload_mesh");
  });
}

}  // extern "C"
