#include "animation/reference_check.h"

#include <algorithm>
#include <string>

namespace deform::animation {
namespace {

grpc::Status Differs(const std::string& what, long long server, long long local) {
  return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                      "the server's mesh is not the local reference's: " + what + " " +
                          std::to_string(server) + " on the server, " + std::to_string(local) +
                          " locally");
}

}  // namespace

grpc::Status CheckServerMatchesReference(client::DeformClient& client,
                                         const deform::v1::MeshSummary& summary,
                                         const DeformationModel& model, const VertexOrder& order) {
  const int solved = model.mesh().num_vertices();
  if (static_cast<int>(summary.vertex_count()) != order.frame_vertices()) {
    return Differs("vertices per frame", summary.vertex_count(), order.frame_vertices());
  }
  if (summary.solved_vertex_count() != 0 &&
      static_cast<int>(summary.solved_vertex_count()) != solved) {
    return Differs("solved vertices", summary.solved_vertex_count(), solved);
  }
  if (static_cast<int>(summary.triangle_count()) != model.mesh().num_triangles()) {
    return Differs("triangles", summary.triangle_count(), model.mesh().num_triangles());
  }
  if (static_cast<int>(summary.bone_count()) != model.skeleton().num_bones()) {
    return Differs("bones", summary.bone_count(), model.skeleton().num_bones());
  }
  const bool server_weights = summary.binding() == deform::v1::BINDING_WEIGHTS;
  if (server_weights != model.weights_given()) {
    return Differs("binding from given weights (1) or through the body (0)", server_weights,
                   model.weights_given());
  }

  deform::v1::GetMeshInfoResponse info;
  grpc::Status fetched = client.GetMeshInfo(summary.mesh_id(), /*include_geometry=*/true, &info);
  if (!fetched.ok()) return fetched;
  Positions server_rest;
  const Status decoded = order.ToModelOrder(info.rest_positions(), &server_rest);
  if (!decoded.ok()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "rest positions: " + decoded.message());
  }
  const Positions& local = model.mesh().vertices;
  // float32 on the wire: a relative rounding of 6e-8 of the largest coordinate.
  const double scale = std::max(model.bounding_box_diagonal(), local.cwiseAbs().maxCoeff());
  const double tolerance = 1e-6 * scale;
  for (Eigen::Index v = 0; v < local.rows(); ++v) {
    const double distance = (server_rest.row(v) - local.row(v)).norm();
    if (!(distance <= tolerance)) {
      return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                          "the server's mesh is not the local reference's: solved vertex " +
                              std::to_string(v) + " rests " + std::to_string(distance) +
                              " from the local one");
    }
  }
  return grpc::Status::OK;
}

}  // namespace deform::animation
