#include "core/base/pose_spec.h"

#include <utility>

#include "core/base/text.h"

namespace deform {
namespace {

StatusOr<PoseSpecTerm> ParseTerm(std::string_view text) {
  const std::vector<std::string_view> fields = Split(text, ':');
  const auto malformed = [&text] {
    return Status::InvalidArgument("pose term '" + std::string(text) +
                                   "' is not JOINT:AXIS:DEGREES");
  };
  if (fields.size() != 3) return malformed();
  PoseSpecTerm term;
  term.joint = std::string(Trim(fields[0]));
  term.axis = std::string(Trim(fields[1]));
  if (term.joint.empty() || term.axis.empty()) return malformed();
  const std::string_view degrees = Trim(fields[2]);
  if (!ParseFiniteDouble(degrees, &term.degrees)) {
    return Status::InvalidArgument("pose term '" + std::string(text) + "': '" +
                                   std::string(degrees) + "' is not a finite number of degrees");
  }
  return term;
}

}  // namespace

StatusOr<std::vector<PoseSpecTerm>> ParsePoseSpecTerms(std::string_view spec) {
  std::vector<PoseSpecTerm> terms;
  spec = Trim(spec);
  if (spec.empty() || spec == "rest") return terms;
  for (std::string_view text : Split(spec, ',')) {
    DEFORM_ASSIGN_OR_RETURN(PoseSpecTerm term, ParseTerm(Trim(text)));
    terms.push_back(std::move(term));
  }
  return terms;
}

}  // namespace deform
