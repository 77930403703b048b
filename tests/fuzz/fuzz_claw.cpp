// SPDX-License-Identifier: BSD-3-Clause
// The claw-description loader and the claw mask: the input is a
// description file's text (beside it a small valid mesh, `box.ply`, that it
// may name). A description that loads is posed and cut out of a small
// depth frame. Contract: errors are std::runtime_error / invalid_argument;
// a loaded claw gives finite vertices and the mask zeroes at most every
// pixel.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/claw/claw_mask.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/io/ply.hpp"

using namespace graspfill;
namespace fs = std::filesystem;

namespace {
const fs::path& Dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("graspfill_fuzz_claw_" + std::to_string(::getpid()));
    fs::create_directories(d);
    TriangleMesh box;
    box.vertices = {{-0.01f, -0.01f, 0.0f},
                    {0.01f, -0.01f, 0.0f},
                    {0.01f, 0.01f, 0.0f},
                    {-0.01f, 0.01f, 0.0f},
                    {0.0f, 0.0f, 0.02f}};
    box.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}, {0, 2, 1}, {0, 3, 2}};
    io::WriteMeshPly((d / "box.ply").string(), box);
    return d;
  }();
  return dir;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path path = Dir() / "claw.json";
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    const claw::ClawModel model = claw::ClawModel::Load(path.string());
    const TriangleMesh posed = model.Posed(0.02, {0.01, 0.02});
    for (const Eigen::Vector3f& v : posed.vertices) FUZZ_CHECK(v.allFinite());
    claw::ClawMask mask;
    mask.SetClaw(posed);
    DepthFrame frame;
    frame.intrinsics = CameraIntrinsics{64, 48, 60.0, 60.0, 32.0, 24.0};
    frame.depth_m.assign(64 * 48, 0.4f);
    Eigen::Isometry3d T_C_G = Eigen::Isometry3d::Identity();
    T_C_G.translation() = Eigen::Vector3d(0, 0, 0.3);
    const int zeroed = mask.Apply(T_C_G, &frame);
    FUZZ_CHECK(zeroed >= 0 && zeroed <= 64 * 48);
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
