// Every reader of untrusted bytes added for rigs (weights: DMAT ASCII and binary, CSV; glTF: .gltf
// and .glb; skeletons: TGF and JSON) fed a few hundred byte strings derived from valid files:
// truncations, flipped and inserted bytes, extreme 32-bit values written over headers and counts,
// and numbers in JSON replaced by absurd ones. Each must return a Status, never crash, hang or
// allocate without bound (run under the sanitizers to see the rest). Deterministic: fixed seeds.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/io/gltf_writer.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"
#include "core/io/skin_weights_io.h"
#include "tests/core/io/gltf_test_util.h"

namespace deform {
namespace {

constexpr int kVariantsPerInput = 300;

std::string BinaryDmat() {
  std::string bytes = "0 0\n2 3\n";
  for (double value : {1.0, 0.25, 0.0, 0.0, 0.75, 1.0}) {
    char raw[8];
    std::memcpy(raw, &value, 8);
    bytes.append(raw, 8);
  }
  return bytes;
}

// One mutation of `valid`, chosen by `random`.
std::string Mutate(const std::string& valid, std::mt19937* random) {
  std::string bytes = valid;
  const auto pick = [random](std::size_t n) {
    return n == 0 ? std::size_t{0} : std::uniform_int_distribution<std::size_t>(0, n - 1)(*random);
  };
  switch (pick(6)) {
    case 0:  // truncate
      bytes.resize(pick(bytes.size() + 1));
      break;
    case 1:  // flip a few bytes
      for (std::size_t k = 0, n = 1 + pick(8); k < n && !bytes.empty(); ++k) {
        bytes[pick(bytes.size())] ^= static_cast<char>(1 + pick(255));
      }
      break;
    case 2:  // insert random bytes
      bytes.insert(pick(bytes.size() + 1), std::string(1 + pick(16), static_cast<char>(pick(256))));
      break;
    case 3: {  // an extreme 32-bit value over 4 bytes (header fields, counts, lengths)
      static constexpr std::uint32_t kExtremes[] = {0,          1,          0x7fffffff,
                                                    0x80000000, 0xffffffff, 0xfffffff0};
      if (bytes.size() >= 4) {
        const std::uint32_t value = kExtremes[pick(6)];
        std::memcpy(&bytes[pick(bytes.size() - 3)], &value, 4);
      }
      break;
    }
    case 4: {  // a number in text replaced by an absurd one
      static const char* kNumbers[] = {"-1", "4294967296", "99999999999999999999", "1e308", "nan",
                                       "0",  "2147483647"};
      std::vector<std::size_t> digits;
      for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (bytes[i] >= '0' && bytes[i] <= '9' &&
            (i == 0 || bytes[i - 1] < '0' || bytes[i - 1] > '9')) {
          digits.push_back(i);
        }
      }
      if (!digits.empty()) {
        const std::size_t start = digits[pick(digits.size())];
        std::size_t end = start;
        while (end < bytes.size() && bytes[end] >= '0' && bytes[end] <= '9') ++end;
        bytes.replace(start, end - start, kNumbers[pick(7)]);
      }
      break;
    }
    default:  // duplicate a slice
      if (!bytes.empty()) {
        const std::size_t start = pick(bytes.size());
        bytes.insert(pick(bytes.size() + 1), bytes.substr(start, 1 + pick(64)));
      }
      break;
  }
  return bytes;
}

// Feeds `read` the variants of `valid`; counts the ones it accepts (to show the mutations reach
// past the first check) and expects the valid input itself to be read.
void Fuzz(const std::string& name, const std::string& valid,
          const std::function<Status(const std::string&)>& read) {
  ASSERT_TRUE(read(valid).ok()) << name
                                << ": the valid input is refused: " << read(valid).ToString();
  std::mt19937 random(20240611u + static_cast<unsigned>(name.size()));
  int accepted = 0;
  for (int k = 0; k < kVariantsPerInput; ++k) {
    const std::string variant = Mutate(valid, &random);
    const Status status = read(variant);
    if (status.ok()) ++accepted;
    if (!status.ok()) {
      EXPECT_FALSE(status.message().empty()) << name << " variant " << k;
      EXPECT_NE(status.code(), StatusCode::kInternal) << name << ": " << status.ToString();
    }
  }
  ::testing::Test::RecordProperty(name + "_accepted", accepted);
}

TEST(ReaderFuzz, WeightsReadersReturnAStatusOnMutatedFiles) {
  const auto dmat = [](const std::string& bytes) {
    return ReadSkinWeights(bytes, SkinWeightsFormat::kDmat).status();
  };
  Fuzz("dmat_ascii", "2 3\n1\n0.25\n0\n0 0.75 1\n", dmat);
  Fuzz("dmat_binary", BinaryDmat(), dmat);
  Fuzz("csv", "vertex,bone,weight\n# c\n0,0,1\n1,1,0.5\n1,0,0.5\n2,1,1\n",
       [](const std::string& bytes) {
         return ReadSkinWeights(bytes, SkinWeightsFormat::kCsv).status();
       });
}

TEST(ReaderFuzz, GltfReaderReturnsAStatusOnMutatedFiles) {
  const gltf_test::TestRig tube = gltf_test::Tube(4, 3);
  const auto read = [](const std::string& bytes) { return ReadGltf(bytes).status(); };
  for (GltfContainer container : {GltfContainer::kGltf, GltfContainer::kGlb}) {
    auto bytes = WriteGltf(tube.mesh, tube.skeleton, tube.weights, container);
    ASSERT_TRUE(bytes.ok());
    Fuzz(container == GltfContainer::kGlb ? "glb" : "gltf", *bytes, read);
  }
}

TEST(ReaderFuzz, SkeletonReadersReturnAStatusOnMutatedFiles) {
  Fuzz("tgf", "1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2\n2 3\n#\n",
       [](const std::string& bytes) { return ParseTgf(bytes).status(); });
  Fuzz("skeleton_json",
       R"({"joints": [{"name": "a", "position": [0, 0, 0]},
                      {"name": "b", "position": [0, 1, 0],
                       "dofs": [{"name": "f", "axis": [1, 0, 0], "min": -5, "max": 90}]},
                      {"name": "c", "position": [0, 2, 0]}],
           "bones": [["a", "b"], ["b", 2]]})",
       [](const std::string& bytes) { return ParseSkeletonJson(bytes).status(); });
}

}  // namespace
}  // namespace deform
