// Text and number helpers for the mesh format checks: reading numbers exactly as OpenMesh's text
// readers (std::istream >>) accept them, and writing them back in their shortest exact form.
#include <cfloat>
#include <charconv>
#include <cmath>
#include <locale>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "mesh_io_internal.h"

namespace deform::mesh_io_internal {
namespace {

char ToLower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// [+-] digits [. digits] [e [+-] digits], with digits on at least one side of the point.
bool IsDecimalSyntax(std::string_view t) {
  std::size_t i = 0;
  const auto skip_digits = [&t, &i] {
    const std::size_t start = i;
    while (i < t.size() && IsDigit(t[i])) ++i;
    return i - start;
  };
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  std::size_t mantissa_digits = skip_digits();
  if (i < t.size() && t[i] == '.') {
    ++i;
    mantissa_digits += skip_digits();
  }
  if (mantissa_digits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    if (skip_digits() == 0) return false;
  }
  return i == t.size();
}

bool IsNonFiniteWord(std::string_view token) {
  if (!token.empty() && (token.front() == '+' || token.front() == '-')) token.remove_prefix(1);
  return EqualsIgnoreCase(token, "nan") || EqualsIgnoreCase(token, "inf") ||
         EqualsIgnoreCase(token, "infinity") || StartsWithIgnoreCase(token, "nan(");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Text

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (ToLower(a[i]) != ToLower(b[i])) return false;
  }
  return true;
}

bool StartsWithIgnoreCase(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && EqualsIgnoreCase(text.substr(0, prefix.size()), prefix);
}

std::string Quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 32;
  std::string shown(token.substr(0, kMaxShown));
  for (char& c : shown) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  if (token.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

void SplitTokens(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && IsSpace(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !IsSpace(line[pos])) ++pos;
    if (pos > start) tokens->push_back(line.substr(start, pos - start));
  }
}

// ---------------------------------------------------------------------------------------------
// Numbers

bool ParseInteger(std::string_view token, long long* value) {
  // One sign at most: "+-1" and "++1" are not integers (OpenMesh's reader fails on them).
  const bool plus = !token.empty() && token.front() == '+';
  if (plus) token.remove_prefix(1);
  if (token.empty() || token.front() == '+' || (plus && token.front() == '-')) return false;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, *value);
  return error == std::errc() && stop == end;
}

RealParse ParseReal(std::string_view token, double* value) {
  if (IsNonFiniteWord(token)) return RealParse::kNonFinite;
  if (!IsDecimalSyntax(token)) return RealParse::kMalformed;
  if (token.front() == '+') token.remove_prefix(1);
  double parsed = 0.0;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, parsed);
  if (error == std::errc::result_out_of_range) {
    // from_chars reports underflow like overflow; underflow reads as (nearly) zero.
    std::istringstream stream{std::string(token)};
    stream.imbue(std::locale::classic());
    stream >> parsed;
    if (stream.fail()) return RealParse::kNonFinite;
  } else if (error != std::errc() || stop != end) {
    return RealParse::kMalformed;
  }
  if (!(std::fabs(parsed) <= FLT_MAX)) return RealParse::kNonFinite;
  *value = parsed;
  return RealParse::kOk;
}

void AppendReal(std::string* out, double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, error == std::errc() ? end : buffer);
}

void AppendInteger(std::string* out, long long value) {
  char buffer[24];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, error == std::errc() ? end : buffer);
}

}  // namespace deform::mesh_io_internal
