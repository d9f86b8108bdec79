// Mesh ids: "mesh-" followed by 32 lower-case hex digits, 128 bits from the kernel's CSPRNG
// (getrandom(2)). Unguessable, so one client cannot name another's mesh by counting, and never
// reused in practice (after 2^32 ids the chance that any two collide is about 2^-65; the registry
// also draws again if a new id equals a loaded one), so an id a client kept across a server
// restart is NOT_FOUND rather than another patient's mesh.
#pragma once

#include <string>
#include <string_view>

namespace deform::service {

// A new random id. Aborts the process if the kernel's random source fails (it does not on Linux
// >= 3.17 once the pool is initialized; an id from a weaker source would be worse than no id).
std::string NewMeshId();

// True for text of NewMeshId()'s form (used to check ids read back from a store).
bool LooksLikeMeshId(std::string_view text);

}  // namespace deform::service
