// The frame encodings on the shared meshes along a flexion trajectory (0 to 120 degrees in 24
// frames of the paper's model; the 1.6k and 26k legs' knee, the 133k arm's elbow in its natural
// direction, the phantom where ../shared/data is absent).
//
// Encode/<encoding>/<mesh> times encoding one frame (cycling through the trajectory), Decode the
// same frames' decoding; both report
//   bytes_per_vertex  the coded positions' bytes over the vertex count, mean over the trajectory
//                     (predicted frames: with their bone transforms, 48 bytes per bone)
//   max_error_diag    the largest per-coordinate distance of a decoded coordinate from the solved
//                     one over the trajectory, as a fraction of the bounding-box diagonal
// Predicted frames are coded at the server's default error (codec::kDefaultPredictedMaxError).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_meshes.h"
#include "core/base/build_info.h"
#include "core/codec/frame_codec.h"

namespace deform::bench {
namespace {

constexpr int kTrajectoryFrames = 24;

struct Trajectory {
  int num_vertices = 0;
  int num_bones = 0;
  double diagonal = 0;
  std::vector<std::vector<double>> frames;     // solved, 3 n each
  std::vector<std::vector<float>> transforms;  // 12 per bone each
  std::vector<float> rest;
  codec::PredictionWeights weights;
};

std::shared_ptr<const Trajectory> TrajectoryFor(const BenchMesh& mesh) {
  static std::map<std::string, std::shared_ptr<const Trajectory>> cache;
  if (auto it = cache.find(mesh.name); it != cache.end()) return it->second;
  auto model = ModelFor(mesh);
  if (!model) return nullptr;
  auto trajectory = std::make_shared<Trajectory>();
  const int n = model->mesh().num_vertices();
  trajectory->num_vertices = n;
  trajectory->num_bones = model->skeleton().num_bones();
  trajectory->diagonal = model->bounding_box_diagonal();
  trajectory->rest.assign(model->mesh().vertices.data(), model->mesh().vertices.data() + 3 * n);
  const BoneWeights& bw = model->bone_weights();
  trajectory->weights = codec::TopFourWeights(bw.offsets, bw.bones, bw.weights, {});
  DeformScratch scratch = model->MakeScratch();
  for (int f = 0; f < kTrajectoryFrames; ++f) {
    const double degrees = 120.0 * f / (kTrajectoryFrames - 1);
    const Pose pose = PoseFromSpecOrRest(*model, mesh.flexion_prefix + std::to_string(degrees));
    model->Deform(*model->default_factorization(), pose, &scratch);
    trajectory->frames.emplace_back(scratch.solution.data(), scratch.solution.data() + 3 * n);
    std::vector<float> transforms(12 * trajectory->num_bones);
    for (int k = 0; k < trajectory->num_bones; ++k) {
      const RigidTransform& bone = scratch.bone_transforms[k];
      const Eigen::Matrix3d r = bone.rotation.toRotationMatrix();
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) transforms[12 * k + 4 * row + col] = r(row, col);
        transforms[12 * k + 4 * row + 3] = static_cast<float>(bone.translation[row]);
      }
    }
    trajectory->transforms.push_back(std::move(transforms));
  }
  return cache[mesh.name] = trajectory;
}

std::unique_ptr<codec::FrameEncoder> EncoderFor(const Trajectory& t, bool predicted) {
  if (!predicted) return std::make_unique<codec::FrameEncoder>(t.num_vertices);
  return std::make_unique<codec::FrameEncoder>(t.rest, t.weights, t.num_bones,
                                               2 * codec::kDefaultPredictedMaxError * t.diagonal);
}

struct CodedTrajectory {
  std::vector<std::vector<unsigned char>> bytes;
  std::vector<codec::EncodedFrameHeader> headers;
  double bytes_per_vertex = 0;
  double max_error_diag = 0;
};

// Every frame coded, then decoded to measure the error.
CodedTrajectory CodeAll(const Trajectory& t, bool predicted) {
  CodedTrajectory coded;
  auto encoder = EncoderFor(t, predicted);
  codec::FrameDecoder decoder(t.num_vertices);
  if (predicted) (void)decoder.SetPrediction(t.rest, t.weights, t.num_bones);
  std::vector<float> decoded(3 * t.num_vertices);
  double total_bytes = 0;
  for (int f = 0; f < kTrajectoryFrames; ++f) {
    std::vector<unsigned char> bytes(encoder->max_encoded_bytes());
    codec::EncodedFrameHeader header;
    bytes.resize(
        encoder->Encode(t.frames[f].data(), {}, t.transforms[f].data(), &header, bytes.data()));
    total_bytes += bytes.size();
    if (header.encoding == codec::FrameEncoding::kPredicted) total_bytes += 48.0 * t.num_bones;
    (void)decoder.Decode(header, bytes.data(), bytes.size(), t.transforms[f].data(),
                         t.transforms[f].size(), decoded.data());
    for (int k = 0; k < 3 * t.num_vertices; ++k) {
      coded.max_error_diag =
          std::max(coded.max_error_diag, std::abs(decoded[k] - t.frames[f][k]) / t.diagonal);
    }
    coded.bytes.push_back(std::move(bytes));
    coded.headers.push_back(header);
  }
  coded.bytes_per_vertex = total_bytes / kTrajectoryFrames / t.num_vertices;
  return coded;
}

void ReportCounters(benchmark::State& state, const CodedTrajectory& coded) {
  state.counters["bytes_per_vertex"] = coded.bytes_per_vertex;
  state.counters["max_error_diag"] = coded.max_error_diag;
}

void BM_Encode(benchmark::State& state, const BenchMesh& mesh, bool predicted) {
  auto t = TrajectoryFor(mesh);
  if (!t) return state.SkipWithError("model could not be built");
  auto encoder = EncoderFor(*t, predicted);
  std::vector<unsigned char> bytes(encoder->max_encoded_bytes());
  codec::EncodedFrameHeader header;
  int f = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        encoder->Encode(t->frames[f].data(), {}, t->transforms[f].data(), &header, bytes.data()));
    f = (f + 1) % kTrajectoryFrames;
  }
  ReportCounters(state, CodeAll(*t, predicted));
}

void BM_Decode(benchmark::State& state, const BenchMesh& mesh, bool predicted) {
  auto t = TrajectoryFor(mesh);
  if (!t) return state.SkipWithError("model could not be built");
  const CodedTrajectory coded = CodeAll(*t, predicted);
  codec::FrameDecoder decoder(t->num_vertices);
  if (predicted) (void)decoder.SetPrediction(t->rest, t->weights, t->num_bones);
  std::vector<float> positions(3 * t->num_vertices);
  int f = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decoder.Decode(coded.headers[f], coded.bytes[f].data(),
                                            coded.bytes[f].size(), t->transforms[f].data(),
                                            t->transforms[f].size(), positions.data()));
    f = (f + 1) % kTrajectoryFrames;
  }
  ReportCounters(state, coded);
}

}  // namespace
}  // namespace deform::bench

int main(int argc, char** argv) {
  using namespace deform::bench;
  if (deform::PrintVersionIfAsked(argc, argv, "deform_codec_bench")) return 0;
  benchmark::Initialize(&argc, argv);
  benchmark::AddCustomContext("build", deform::VersionLine("deform_codec_bench"));
  for (const BenchMesh& mesh : AvailableMeshes()) {
    for (const bool predicted : {false, true}) {
      const std::string encoding = predicted ? "predicted" : "quantized";
      benchmark::RegisterBenchmark(("Encode/" + encoding + "/" + mesh.name).c_str(), BM_Encode,
                                   mesh, predicted)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("Decode/" + encoding + "/" + mesh.name).c_str(), BM_Decode,
                                   mesh, predicted)
          ->Unit(benchmark::kMillisecond);
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
