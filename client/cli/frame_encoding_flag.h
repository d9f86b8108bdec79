// The --encoding flag shared by the command-line clients: how a stream's frames travel
// (deform.v1.FrameEncoding). Header-only; the clients link CLI11.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <sstream>
#include <string>

#include "cli/enum_flag.h"
#include "core/codec/frame_codec.h"
#include "deform/v1/deform.pb.h"

namespace deform::cli {

inline const std::map<std::string, deform::v1::FrameEncoding>& FrameEncodingNames() {
  static const std::map<std::string, deform::v1::FrameEncoding> names = {
      {"float32", deform::v1::FRAME_ENCODING_FLOAT32},
      {"quantized", deform::v1::FRAME_ENCODING_QUANTIZED},
      {"predicted", deform::v1::FRAME_ENCODING_PREDICTED}};
  return names;
}

inline std::string FrameEncodingName(deform::v1::FrameEncoding encoding) {
  return NameOf(FrameEncodingNames(), encoding, "float32");
}

// The flag's help; the predicted frames' error is the codec's default (core/codec/frame_codec.h).
inline std::string FrameEncodingHelp() {
  std::ostringstream help;
  help << "How frames travel: float32 (12 bytes per vertex), quantized (16 bits in the frame's "
          "box, meshoptimizer's vertex codec) or predicted (the residual against skinning both "
          "sides compute, within "
       << codec::kDefaultPredictedMaxError << " of the diagonal)";
  return help.str();
}

inline CLI::Option* AddFrameEncodingFlag(CLI::App& app, deform::v1::FrameEncoding* encoding) {
  return AddEnumFlag(app, "--encoding", encoding, FrameEncodingNames(), FrameEncodingHelp(),
                     "float32");
}

// Bytes a frame's positions took on the wire: its encoded positions, or its float32 ones.
inline std::size_t FramePayloadBytes(const deform::v1::DeformFrame& frame) {
  return frame.has_encoded() ? frame.encoded().ByteSizeLong() : frame.positions().size();
}

}  // namespace deform::cli
