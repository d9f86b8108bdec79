// Text helpers with no dependency beyond the standard library, shared by the readers, the pose
// syntax (pose_spec.h) and the client library. Locale-independent.
#pragma once

#include <string_view>
#include <vector>

namespace deform {

// ASCII whitespace: ' ', '\t', '\n', '\v', '\f', '\r'.
inline bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// `text` without leading and trailing whitespace (a view into `text`).
std::string_view Trim(std::string_view text);

// The parts of `text` between `separator`s, empty parts included: n separators give n + 1 parts.
// The parts are views into `text`.
std::vector<std::string_view> Split(std::string_view text, char separator);

// The whole of `text` as a finite decimal number: [+|-] digits [. digits] [e [+|-] digits], with
// digits on at least one side of the point, nothing before or after it (no whitespace). False,
// leaving `*value` alone, for anything else: empty text, trailing characters, hexadecimal, "inf",
// "nan", or a magnitude beyond double range. Correctly rounded.
bool ParseFiniteDouble(std::string_view text, double* value);

// The whole of `text` as a decimal int ([-] digits, no whitespace, within int range). False,
// leaving `*value` alone, otherwise.
bool ParseInt(std::string_view text, int* value);

}  // namespace deform
