#include "service/transport/http_host_policy.h"

#include <algorithm>
#include <cctype>

#include "service/base/listen_address.h"

namespace deform::web {
namespace {

std::string Lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool AllDigits(std::string_view text) {
  return !text.empty() && text.size() <= 5 &&
         std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
}

bool HostChar(unsigned char c) { return std::isalnum(c) || c == '-' || c == '.' || c == '_'; }

bool IsWildcard(std::string_view name) {
  return name.empty() || name == "0.0.0.0" || name == "::" || name == "[::]";
}

}  // namespace

std::optional<std::string> HostNameOf(std::string_view host_header) {
  if (host_header.empty()) return std::nullopt;
  if (host_header.front() == '[') {
    const std::size_t close = host_header.find(']');
    if (close == std::string_view::npos || close == 1) return std::nullopt;
    const std::string_view inside = host_header.substr(1, close - 1);
    const std::string_view rest = host_header.substr(close + 1);
    if (!rest.empty() && (rest.front() != ':' || !AllDigits(rest.substr(1)))) return std::nullopt;
    const bool v6 = std::all_of(inside.begin(), inside.end(), [](unsigned char c) {
      return std::isxdigit(c) || c == ':' || c == '.';
    });
    if (!v6) return std::nullopt;
    return Lower(inside);
  }
  const std::size_t colon = host_header.find(':');
  const std::string_view name = host_header.substr(0, colon);
  if (colon != std::string_view::npos && !AllDigits(host_header.substr(colon + 1))) {
    return std::nullopt;
  }
  if (name.empty() || !std::all_of(name.begin(), name.end(), HostChar)) return std::nullopt;
  return Lower(name);
}

HttpHostPolicy::HttpHostPolicy(std::string_view listen_address,
                               const std::vector<std::string>& extra_hosts)
    : names_{"localhost", "127.0.0.1", "::1"} {
  const auto add = [this](std::string_view name) {
    if (name.size() >= 2 && name.front() == '[' && name.back() == ']') {
      name = name.substr(1, name.size() - 2);
    }
    std::string lower = Lower(name);
    if (IsWildcard(lower)) return;
    if (std::find(names_.begin(), names_.end(), lower) == names_.end()) names_.push_back(lower);
  };
  add(service::SplitListenAddress(listen_address).host);
  for (const std::string& host : extra_hosts) add(host);
}

bool HttpHostPolicy::AllowsHost(std::string_view host_header) const {
  const std::optional<std::string> name = HostNameOf(host_header);
  return name.has_value() && std::find(names_.begin(), names_.end(), *name) != names_.end();
}

bool HttpHostPolicy::AllowsRequest(std::string_view host_header,
                                   std::optional<std::string_view> origin) const {
  if (!AllowsHost(host_header)) return false;
  if (!origin.has_value()) return true;
  return Lower(*origin) == "http://" + Lower(host_header);
}

}  // namespace deform::web
