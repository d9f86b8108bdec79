// Tests of reading OFF data (core/mesh_io.h): malformed input is named. Valid OFF data is read
// in the every-format tests of mesh_io_test.cc.
//
// Malformed inputs are written as bytes in the tests themselves. Many of them used to hang, abort
// or crash OpenMesh's OFF reader before the checks in mesh_io_off.cc; each is noted below.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/io/mesh_io.h"
#include "tests/core/io/mesh_io_test_util.h"

namespace deform::mesh_io_test {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading: malformed input names the problem (and neither hangs nor crashes)

TEST(ReadMeshTest, MalformedOffIsNamed) {
  ExpectRefusals(
      MeshFormat::kOff,
      {// OpenMesh looped over the declared face count without looking for the end of the data.
       {"a truncated file declaring 4 million faces",
        "OFF\n3 4000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "ends inside face 1 of 4000000"},
       {"the COFF variant", "COFF\n3 1 0\n0 0 0 1 1 1\n1 0 0 1 1 1\n0 1 0 1 1 1\n3 0 1 2\n",
        "exactly 'OFF'"},
       {"face colours", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255 0 0\n",
        "face colours are not supported"},
       {"an infinite coordinate", "OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n",
        "vertex 1 has a non-finite coordinate"}});
}

TEST(ReadMeshTest, OffIndexWithTwoSignsIsInvalid) {
  // "+-1" once reached OpenMesh, whose reader failed on it and left the index uninitialized.
  const auto result = ReadMesh("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 +-1 2 1\n", MeshFormat::kOff);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace deform::mesh_io_test
