// The checks of a LoadMesh header that need nothing but the header and the limits: its strings'
// lengths, the source (phantom size, an upload's formats and parts), and an upload's declared size
// (compared without overflow). The LoadMesh reactor runs them before reserving anything; the fuzz
// target `load_header_fuzz` runs them on arbitrary bytes. Pure functions, thread-safe.
#pragma once

#include <cstdint>

#include "core/base/status.h"
#include "core/io/mesh_io.h"
#include "core/io/skin_weights_io.h"
#include "deform/v1/deform.pb.h"
#include "service/base/service_options.h"

namespace deform::service {

// The core's reader format of an upload's mesh format (glTF excluded: it has a reader of its
// own). INVALID_ARGUMENT for unspecified or unknown values.
StatusOr<MeshFormat> CoreMeshFormat(v1::MeshFormat format);
StatusOr<SkinWeightsFormat> CoreWeightsFormat(v1::SkinWeightsFormat format);

// OK when `header` may start a load under `limits`: INVALID_ARGUMENT naming the field for a
// string over its limit (request_limits.h), a negative phantom size, an upload without a mesh
// size, a known format, or a skeleton where one is needed (a glTF rig brings its own skeleton and
// weights and takes neither), a bone surface without a mesh, a bone or a known mesh format (not
// glTF); RESOURCE_EXHAUSTED for a phantom over max_vertices, an upload over max_upload_bytes
// (with the real declared figures) or bone surfaces over max_bone_surface_bytes.
Status CheckLoadHeader(const v1::LoadMeshHeader& header, const ServiceLimits& limits);

// The bytes of an upload's bone surface files together (0 for a phantom).
std::uint64_t BoneSurfaceBytes(const v1::LoadMeshHeader& header);

}  // namespace deform::service
