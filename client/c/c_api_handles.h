// The structs behind the C API's client and mesh handles (deform_stream is in deform_c_stream.cc,
// beside what its callbacks fill). Each holds a shared_ptr to the C++ client it came from, so
// handles may be freed in any order.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "deform_client.h"

struct deform_client {
  std::shared_ptr<deform::client::DeformClient> client;
};

struct deform_mesh {
  std::shared_ptr<deform::client::DeformClient> client;
  deform::v1::MeshSummary summary;  // as the server reported it when the handle was made

  std::mutex geometry_mutex;
  bool geometry_loaded = false;  // guarded by geometry_mutex, as are the two below
  std::vector<float> rest_positions;
  std::vector<std::uint32_t> triangles;
  struct BoneSurfaceGeometry {
    std::vector<float> rest_positions;
    std::vector<std::uint32_t> triangles;
  };
  std::vector<BoneSurfaceGeometry> bone_surfaces;  // MeshSummary.bone_surfaces' order
};
