// SPDX-License-Identifier: BSD-3-Clause
// The fuzz targets' contracts, in the normal suite, on every committed
// input: the seed corpora (tests/fuzz/corpus/) and the inputs the fuzzers
// found crashes with (tests/fuzz/regressions/<target>/). A message that
// decodes must encode and decode again; the log reader never reads past
// the file; the cloud-slice assembler keeps its contract; the PLY
// parser's errors name the file.
#include <gtest/gtest.h>

#include <algorithm>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "cloud_chunks_feed.hpp"
#include "graspfill/io/collision_mesh_message.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "ply_parser.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

std::vector<std::vector<uint8_t>> Inputs(const std::string& target) {
  std::vector<std::vector<uint8_t>> inputs;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path dir = fs::path(GRASPFILL_SOURCE_DIR) / "tests" / "fuzz" / kind / target;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      std::ifstream in(entry.path(), std::ios::binary);
      inputs.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
  }
  return inputs;
}

TEST(FuzzRegressions, DecodedObjectCloudsReEncode) {
  const auto inputs = Inputs("object_cloud");
  ASSERT_GE(inputs.size(), 2u);
  for (const auto& bytes : inputs) {
    ObjectCloud cloud;
    std::string error;
    if (!DecodeObjectCloud(bytes.data(), bytes.size(), &cloud, &error)) continue;
    std::vector<uint8_t> again;
    // Threw std::logic_error on a frame name with an embedded NUL.
    ASSERT_NO_THROW(again = EncodeObjectCloud(cloud)) << cloud.frame_name;
    ObjectCloud back;
    EXPECT_TRUE(DecodeObjectCloud(again.data(), again.size(), &back, &error)) << error;
    EXPECT_EQ(back.frame_name, cloud.frame_name);
  }
}

TEST(FuzzRegressions, DecodedSessionDescriptionsReEncode) {
  const auto inputs = Inputs("session_description");
  ASSERT_GE(inputs.size(), 2u);
  for (const auto& bytes : inputs) {
    SessionDescription session;
    std::string error;
    if (!DecodeSessionDescription(bytes.data(), bytes.size(), &session, &error)) continue;
    std::vector<uint8_t> again;
    ASSERT_NO_THROW(again = EncodeSessionDescription(session));
    SessionDescription back;
    EXPECT_TRUE(DecodeSessionDescription(again.data(), again.size(), &back, &error)) << error;
    EXPECT_EQ(back.claw_text, session.claw_text);
  }
}

TEST(FuzzRegressions, StringsWithAnEmbeddedNulAreMalformed) {
  ObjectCloud cloud;
  cloud.frame_name = "abc";
  std::vector<uint8_t> bytes = EncodeObjectCloud(cloud);
  const std::string needle = "abc";
  const auto at = std::search(bytes.begin(), bytes.end(), needle.begin(), needle.end());
  ASSERT_NE(at, bytes.end());
  *(at + 1) = 0;  // "a\0c"
  std::string error;
  MessageError reason = MessageError::kNone;
  EXPECT_FALSE(DecodeObjectCloud(bytes.data(), bytes.size(), &cloud, &error, &reason));
  EXPECT_EQ(reason, MessageError::kMalformed);
}

TEST(FuzzRegressions, DepthGripperStatusAndLogInputsKeepTheirContracts) {
  for (const auto& bytes : Inputs("depth_image")) {
    DepthFrame frame;
    std::string error;
    if (!DecodeDepthImage(bytes.data(), bytes.size(), &frame, &error)) continue;
    const auto again = EncodeDepthImage(frame, DepthEncoding::kZlib16, 0.001);
    DepthFrame back;
    EXPECT_TRUE(DecodeDepthImage(again.data(), again.size(), &back, &error)) << error;
  }
  for (const auto& bytes : Inputs("gripper_state")) {
    GripperState state;
    std::string error;
    if (!DecodeGripperState(bytes.data(), bytes.size(), Eigen::Isometry3d::Identity(), &state, &error))
      continue;
    const auto again = EncodeGripperState(state);
    GripperState back;
    EXPECT_TRUE(DecodeGripperState(again.data(), again.size(), Eigen::Isometry3d::Identity(), &back, &error));
  }
  for (const auto& bytes : Inputs("module_status")) {
    ModuleStatus status;
    std::string error;
    if (!DecodeModuleStatus(bytes.data(), bytes.size(), &status, &error)) continue;
    std::vector<uint8_t> again;
    ASSERT_NO_THROW(again = EncodeModuleStatus(status));
    ModuleStatus back;
    EXPECT_TRUE(DecodeModuleStatus(again.data(), again.size(), &back, &error)) << error;
  }
  const auto logs = Inputs("lcm_log_reader");
  ASSERT_GE(logs.size(), 2u);
  for (auto bytes : logs) {
    std::FILE* f = fmemopen(bytes.data(), bytes.size(), "rb");
    ASSERT_NE(f, nullptr);
    LcmLogReader reader(f, static_cast<int64_t>(bytes.size()), "corpus");
    LogEvent event;
    while (reader.Next(&event) == LogReadResult::kEvent) EXPECT_LE(reader.offset(), reader.file_size());
    std::fclose(f);
  }
}

TEST(FuzzRegressions, DecodedCollisionMeshesReEncode) {
  const auto inputs = Inputs("collision_mesh");
  ASSERT_GE(inputs.size(), 2u);
  int decoded = 0;
  for (const auto& bytes : inputs) {
    CollisionMeshMessage mesh;
    std::string error;
    if (!DecodeCollisionMesh(bytes.data(), bytes.size(), &mesh, &error)) continue;
    ++decoded;
    std::vector<uint8_t> again;
    ASSERT_NO_THROW(again = EncodeCollisionMesh(mesh));
    CollisionMeshMessage back;
    ASSERT_TRUE(DecodeCollisionMesh(again.data(), again.size(), &back, &error)) << error;
    EXPECT_EQ(back.mesh.vertices, mesh.mesh.vertices);
    EXPECT_EQ(back.mesh.triangles, mesh.mesh.triangles);
  }
  EXPECT_GE(decoded, 2);  // the seeds
}

TEST(FuzzRegressions, CloudSliceInputsKeepTheAssemblersContract) {
  const auto inputs = Inputs("cloud_chunks");
  ASSERT_GE(inputs.size(), 4u);
  for (const auto& bytes : inputs) {
    EXPECT_EQ(testing::CheckCloudChunkInput(bytes.data(), bytes.size()), "");
  }
}

TEST(FuzzRegressions, PlyInputsParseOrNameTheFile) {
  const auto inputs = Inputs("ply_reader");
  ASSERT_GE(inputs.size(), 4u);
  int parsed = 0;
  for (const auto& bytes : inputs) {
    try {
      const ply::Parsed p =
          ply::Parse(std::string(bytes.begin(), bytes.end()), "f.ply", "cannot read PLY", true);
      ++parsed;
      for (int64_t i : p.face_indices) EXPECT_LT(i, p.num_vertices);
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("'f.ply'"), std::string::npos) << e.what();
    }
  }
  EXPECT_GE(parsed, 4);  // the seeds other than the cut header
}

}  // namespace
}  // namespace graspfill::io
