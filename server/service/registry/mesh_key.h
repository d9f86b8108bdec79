// Mesh keys: a mesh's id is the keyed hash of what determines its model, so that loading the same
// content again names the same mesh, and replicas sharing the secret agree on the name (a
// balancer routes a mesh's streams by it, docs/cluster.md).
//
// key = "mesh-" + the first 128 bits, in lower-case hex, of
//   HMAC-SHA256(secret', "deformd mesh key v1" | tenant | header | mesh bytes)
// with each part length-prefixed (u64 little-endian), `header` the LoadMeshHeader serialized
// deterministically without its name (a label, not the model), and secret' = HMAC-SHA256(secret,
// "deformd mesh keys"), so the store's own seal (mesh_store.h) and the keys never share a key.
// The key has NewMeshId()'s form (mesh_id.h). It cannot be computed (or guessed from the file)
// without the secret; the tenant is part of it, so two tenants' identical uploads are two meshes.
//
// The secret is the store key (--store-key) when there is one, shared by every replica of a
// cluster; otherwise 32 random bytes drawn at start, so keys are stable only within one process.
// Thread-safe (immutable).
#pragma once

#include <string>

#include "deform/v1/deform.pb.h"

namespace deform::service {

class MeshKeys {
 public:
  // Under a fresh random secret.
  MeshKeys();
  // Under `secret` (any length > 0).
  explicit MeshKeys(const std::string& secret);

  std::string KeyOf(const std::string& tenant, const v1::LoadMeshHeader& header,
                    const std::string& mesh_bytes) const;

 private:
  std::string derived_;  // secret'
};

}  // namespace deform::service
