#include "core/base/tool_spec.h"

#include <string>
#include <vector>

#include "core/base/text.h"

namespace deform {

StatusOr<ToolSpec> ParseToolSpecText(std::string_view text) {
  const auto refuse = [&] {
    return Status::InvalidArgument("tool '" + std::string(text) +
                                   "': expected sphere:X,Y,Z,R or capsule:X0,Y0,Z0,X1,Y1,Z1,R");
  };
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos) return refuse();
  const std::string_view shape = text.substr(0, colon);
  ToolSpec spec;
  if (shape == "capsule") {
    spec.capsule = true;
  } else if (shape != "sphere") {
    return refuse();
  }
  const std::size_t expected = spec.capsule ? 7 : 4;
  std::vector<double> values;
  std::string_view rest = text.substr(colon + 1);
  for (;;) {
    const std::size_t comma = rest.find(',');
    double value = 0;
    if (!ParseFiniteDouble(rest.substr(0, comma), &value)) return refuse();
    values.push_back(value);
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  if (values.size() != expected) return refuse();
  for (int c = 0; c < 3; ++c) {
    spec.a[c] = values[c];
    spec.b[c] = spec.capsule ? values[3 + c] : values[c];
  }
  spec.radius = values.back();
  return spec;
}

}  // namespace deform
