#include "animation/animation_script.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include "core/base/text.h"

namespace deform::animation {
namespace {

constexpr std::string_view kRootPrefix = "root=";

Status LineError(int line, const std::string& message) {
  return Status::InvalidArgument("line " + std::to_string(line) + ": " + message);
}

// "TX,TY,TZ,AX,AY,AZ,DEG" into `root`.
Status ParseRoot(std::string_view text, int line, RootPlacement* root) {
  const std::vector<std::string_view> fields = Split(text, ',');
  if (fields.size() != 7) {
    return LineError(line, "root '" + std::string(text) +
                               "' is not TX,TY,TZ,AX,AY,AZ,DEG (seven numbers, got " +
                               std::to_string(fields.size()) + ")");
  }
  double values[7];
  for (int i = 0; i < 7; ++i) {
    if (!ParseFiniteDouble(Trim(fields[i]), &values[i])) {
      return LineError(line, "root field " + std::to_string(i + 1) + " '" +
                                 std::string(Trim(fields[i])) + "' is not a finite number");
    }
  }
  root->translation = {values[0], values[1], values[2]};
  root->axis = {values[3], values[4], values[5]};
  root->degrees = values[6];
  const double axis_length =
      std::sqrt(values[3] * values[3] + values[4] * values[4] + values[5] * values[5]);
  if (root->degrees != 0 && !(axis_length > 0)) {
    return LineError(
        line, "root rotation of " + std::string(Trim(fields[6])) + " degrees about a zero axis");
  }
  if (!(axis_length > 0)) root->axis = {1, 0, 0};
  return Status::Ok();
}

StatusOr<AnimationFrame> ParseFrame(std::string_view text, int line) {
  AnimationFrame frame;
  frame.line = line;
  frame.text = std::string(text);
  const std::size_t semicolon = text.find(';');
  frame.pose_spec = std::string(Trim(text.substr(0, semicolon)));
  auto terms = ParsePoseSpecTerms(frame.pose_spec);
  if (!terms.ok()) return LineError(line, terms.status().message());
  frame.terms = std::move(*terms);
  if (semicolon != std::string_view::npos) {
    const std::string_view extra = Trim(text.substr(semicolon + 1));
    if (extra.substr(0, kRootPrefix.size()) != kRootPrefix) {
      return LineError(line,
                       "'" + std::string(extra) + "' after ';' is not root=TX,TY,TZ,AX,AY,AZ,DEG");
    }
    DEFORM_RETURN_IF_ERROR(ParseRoot(extra.substr(kRootPrefix.size()), line, &frame.root));
    frame.has_root = true;
  }
  return frame;
}

}  // namespace

StatusOr<std::vector<AnimationFrame>> ParseAnimation(std::string_view text) {
  std::vector<AnimationFrame> frames;
  int line = 0;
  for (std::string_view raw : Split(text, '\n')) {
    ++line;
    const std::size_t hash = raw.find('#');
    const std::string_view content = Trim(raw.substr(0, hash));
    if (content.empty()) continue;
    DEFORM_ASSIGN_OR_RETURN(AnimationFrame frame, ParseFrame(content, line));
    frames.push_back(std::move(frame));
  }
  if (frames.empty()) return Status::InvalidArgument("no frame (every line is blank or a comment)");
  return frames;
}

StatusOr<std::vector<AnimationFrame>> ReadAnimationFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound("cannot read animation '" + path + "'");
  std::ostringstream contents;
  contents << in.rdbuf();
  auto frames = ParseAnimation(contents.str());
  if (!frames.ok()) return frames.status().WithContext(path);
  return frames;
}

}  // namespace deform::animation
