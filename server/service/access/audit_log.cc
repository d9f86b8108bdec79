#include "service/access/audit_log.h"

#include <spdlog/spdlog.h>

#include <memory>

#include "service/base/log_text.h"

namespace deform::service {
namespace {

spdlog::logger& AuditLogger() {
  static const std::shared_ptr<spdlog::logger> logger = [] {
    std::shared_ptr<spdlog::logger> existing = spdlog::get("audit");
    if (existing != nullptr) return existing;
    std::shared_ptr<spdlog::logger> created = NewEscapingStdoutLogger("audit");
    // deformd's pattern with the logger's name, so that audit lines can be told apart.
    created->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] [%n] %v");
    // An audit trail, not diagnostics: written whatever --log-level says.
    created->set_level(spdlog::level::info);
    return created;
  }();
  return *logger;
}

}  // namespace

void Audit(std::string_view tenant, std::string_view action, std::string_view mesh_id,
           std::string_view result) {
  AuditLogger().info("tenant={} action={} mesh={} result={}", EscapeForLog(tenant),
                     EscapeForLog(action), mesh_id.empty() ? "-" : EscapeForLog(mesh_id, 80),
                     EscapeForLog(result));
}

void AuditCrossTenant(const Identity& caller, std::string_view owner, std::string_view mesh_id,
                      std::string_view what) {
  if (caller.role != Role::kOperator || caller.tenant.empty() || owner == caller.tenant) return;
  AuditLogger().info("tenant={} action=cross_tenant mesh={} result=owner={} role=operator op={}",
                     EscapeForLog(caller.tenant), EscapeForLog(mesh_id, 80), EscapeForLog(owner),
                     EscapeForLog(what));
}

}  // namespace deform::service
