#include "service/transport/web_auth.h"

#include <vector>

namespace deform::web {
namespace {

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

std::vector<std::string_view> SplitList(std::string_view list) {
  std::vector<std::string_view> items;
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    items.push_back(Trim(list.substr(0, comma)));
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  return items;
}

int Base64UrlValue(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '-') return 62;
  if (c == '_') return 63;
  return -1;
}

}  // namespace

bool DecodeBase64Url(std::string_view text, std::string* out) {
  out->clear();
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  if (text.size() % 4 == 1) return false;
  unsigned buffer = 0;
  int bits = 0;
  for (const char c : text) {
    const int value = Base64UrlValue(c);
    if (value < 0) return false;
    buffer = (buffer << 6) | static_cast<unsigned>(value);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out->push_back(static_cast<char>((buffer >> bits) & 0xFF));
    }
  }
  return true;
}

std::string AuthorizationFromUpgrade(std::string_view authorization_header,
                                     std::string_view subprotocols_header) {
  if (!authorization_header.empty()) return std::string(authorization_header);
  constexpr std::string_view kPrefix = "bearer.";
  for (const std::string_view item : SplitList(subprotocols_header)) {
    if (item.substr(0, kPrefix.size()) != kPrefix) continue;
    std::string token;
    if (!DecodeBase64Url(item.substr(kPrefix.size()), &token)) token.clear();
    return "Bearer " + token;
  }
  return {};
}

bool OffersDeformSubprotocol(std::string_view subprotocols_header) {
  for (const std::string_view item : SplitList(subprotocols_header)) {
    if (item == kWebSocketSubprotocol) return true;
  }
  return false;
}

}  // namespace deform::web
