// Audit lines: who did what to which mesh, and how it ended. One line per call (and per stream
// start and end), through the spdlog logger named "audit", so that a deployment can route it
// apart (spdlog::get("audit")):
//
//     [time] [info] [audit] tenant=ward-3 action=unload mesh=mesh-4f... result=OK
//
// Every field is escaped (EscapeForLog): client strings (mesh ids, names) cannot forge a line.
// The logger logs at info whatever the server's log level (it is created at the first line,
// after deformd set the level).
// `tenant` is "-" for a caller that did not authenticate. Thread-safe.
#pragma once

#include <string_view>

#include "service/access/identity.h"

namespace deform::service {

void Audit(std::string_view tenant, std::string_view action, std::string_view mesh_id,
           std::string_view result);

// An operator's access to a mesh another tenant owns (`what`: find, list, unload):
//     tenant=OPERATOR action=cross_tenant mesh=ID result=owner=OWNER role=operator op=WHAT
// Nothing for a caller's own meshes or for the server's own lookups (an empty tenant).
void AuditCrossTenant(const Identity& caller, std::string_view owner, std::string_view mesh_id,
                      std::string_view what);

}  // namespace deform::service
