#include "core/base/pose_spec.h"

#include <algorithm>
#include <utility>

#include "core/base/text.h"

namespace deform {
namespace {

StatusOr<PoseSpecTerm> ParseTerm(std::string_view text) {
  const auto malformed = [&text] {
    return Status::InvalidArgument("pose term '" + std::string(text) +
                                   "' is not JOINT:AXIS:DEGREES");
  };
  // The axis and the angle are the last two fields; the joint is everything before them (a
  // name may hold colons), or a double-quoted name (which may hold commas and spaces).
  PoseSpecTerm term;
  std::string_view rest = text;
  if (!text.empty() && text.front() == '"') {
    const std::size_t close = text.find('"', 1);
    if (close == std::string_view::npos) return malformed();
    term.joint = std::string(text.substr(1, close - 1));
    rest = Trim(text.substr(close + 1));
    if (rest.empty() || rest.front() != ':') return malformed();
    rest = rest.substr(1);
    if (std::count(rest.begin(), rest.end(), ':') != 1) return malformed();
  } else {
    const std::size_t last = text.rfind(':');
    if (last == std::string_view::npos || last == 0) return malformed();
    const std::size_t axis_start = text.rfind(':', last - 1);
    if (axis_start == std::string_view::npos) return malformed();
    term.joint = std::string(Trim(text.substr(0, axis_start)));
    rest = text.substr(axis_start + 1);
  }
  const std::size_t colon = rest.find(':');
  term.axis = std::string(Trim(rest.substr(0, colon)));
  if (term.joint.empty() || term.axis.empty()) return malformed();
  const std::string_view degrees = Trim(rest.substr(colon + 1));
  if (!ParseFiniteDouble(degrees, &term.degrees)) {
    return Status::InvalidArgument("pose term '" + std::string(text) + "': '" +
                                   std::string(degrees) + "' is not a finite number of degrees");
  }
  return term;
}

// `spec` split at the commas outside double quotes. INVALID_ARGUMENT for an unclosed quote.
StatusOr<std::vector<std::string_view>> SplitTerms(std::string_view spec) {
  std::vector<std::string_view> terms;
  bool quoted = false;
  std::size_t start = 0;
  for (std::size_t i = 0; i < spec.size(); ++i) {
    if (spec[i] == '"') quoted = !quoted;
    if (spec[i] == ',' && !quoted) {
      terms.push_back(spec.substr(start, i - start));
      start = i + 1;
    }
  }
  if (quoted) {
    return Status::InvalidArgument("pose '" + std::string(spec) + "' has an unclosed '\"'");
  }
  terms.push_back(spec.substr(start));
  return terms;
}

}  // namespace

StatusOr<std::vector<PoseSpecTerm>> ParsePoseSpecTerms(std::string_view spec) {
  std::vector<PoseSpecTerm> terms;
  spec = Trim(spec);
  if (spec.empty() || spec == "rest") return terms;
  DEFORM_ASSIGN_OR_RETURN(const std::vector<std::string_view> texts, SplitTerms(spec));
  for (std::string_view text : texts) {
    DEFORM_ASSIGN_OR_RETURN(PoseSpecTerm term, ParseTerm(Trim(text)));
    terms.push_back(std::move(term));
  }
  return terms;
}

}  // namespace deform
