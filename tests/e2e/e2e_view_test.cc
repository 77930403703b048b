// SPDX-License-Identifier: BSD-3-Clause
// Pictures and manners through the real CLI: `graspfill view` (the PNG read
// back: each provenance's colour where its points are), --preview of replay
// and repair, bad input, --version against project(VERSION), the progress
// line only on a terminal (and never with --quiet), line-buffered stdout.
#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/view/contact_sheet.hpp"

namespace graspfill {
namespace {

namespace fs = std::filesystem;
using testing::RunCli;
using testing::ScratchDir;

constexpr double kPi = 3.14159265358979323846;

// A cylinder's side in G, observed but for a strip at mid-height filled
// from the surface, and its cap on the palm side (z = 0) filled by symmetry.
ObjectCloud HeldCylinder() {
  ObjectCloud cloud;
  for (int k = 0; k < 100; ++k) {
    const double z = 0.1 * (k + 0.5) / 100;
    for (int a = 0; a < 100; ++a) {
      const double t = 2 * kPi * a / 100;
      cloud.points_G.emplace_back(0.025 * std::cos(t), 0.025 * std::sin(t), z);
      cloud.provenance.push_back(z > 0.045 && z < 0.055 ? Provenance::kSurface : Provenance::kObserved);
    }
  }
  for (int r = 1; r <= 25; ++r) {
    for (int a = 0; a < 6 * r; ++a) {
      const double t = 2 * kPi * a / (6 * r);
      cloud.points_G.emplace_back(0.001 * r * std::cos(t), 0.001 * r * std::sin(t), 0.0);
      cloud.provenance.push_back(Provenance::kSymmetry);
    }
  }
  return cloud;
}

ObjectCloud ObservedOnly(const ObjectCloud& cloud) {
  ObjectCloud out;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.provenance[i] != Provenance::kObserved) continue;
    out.points_G.push_back(cloud.points_G[i]);
    out.provenance.push_back(Provenance::kObserved);
  }
  return out;
}

open3d::geometry::Image ReadPng(const std::string& path) {
  open3d::geometry::Image image;
  EXPECT_TRUE(open3d::io::ReadImage(path, image)) << path;
  EXPECT_EQ(image.num_of_channels_, 3);
  EXPECT_EQ(image.bytes_per_channel_, 1);
  return image;
}

struct Pixels {
  int count{0};
  double mean_row{0.0};
};

// Whether `pixel` is a shade of `colour` (s * colour, s in [0.4, 1], to
// rounding): the pictures shade each point's colour by depth or normal.
bool IsShadeOf(const uint8_t* pixel, const Rgb8& colour) {
  double dot = 0.0, norm = 0.0;
  for (int k = 0; k < 3; ++k) {
    dot += pixel[k] * static_cast<double>(colour[k]);
    norm += static_cast<double>(colour[k]) * colour[k];
  }
  const double s = dot / norm;
  if (s < 0.4 || s > 1.01) return false;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(pixel[k] - s * colour[k]) > 1.5) return false;
  }
  return true;
}

// Pixels of a shade of the provenance's colour in view `view` of column
// `column` (view::LayoutSheet says where RenderSheet put it).
Pixels InView(const open3d::geometry::Image& image, const view::SheetLayout& layout, int column, int view,
              Provenance p) {
  const Rgb8 c = ProvenanceColor(p);
  Pixels s;
  for (int y = layout.ViewY(view); y < layout.ViewY(view) + layout.view_px; ++y) {
    for (int x = layout.ViewX(column); x < layout.ViewX(column) + layout.view_px; ++x) {
      if (IsShadeOf(&image.data_[(static_cast<size_t>(y) * image.width_ + x) * 3], c)) {
        ++s.count;
        s.mean_row += y;
      }
    }
  }
  if (s.count > 0) s.mean_row /= s.count;
  return s;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ViewCli, PictureShowsEachProvenanceWhereItIs) {
  const std::string dir = ScratchDir("e2e_view_one");
  io::WriteCloudPly(dir + "/cloud.ply", HeldCylinder());
  const auto run = RunCli("view " + dir + "/cloud.ply -o " + dir + "/view.png --views 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const open3d::geometry::Image image = ReadPng(dir + "/view.png");
  view::SheetConfig config;
  config.views = 2;
  const view::SheetLayout layout = view::LayoutSheet(1, config);
  ASSERT_EQ(image.width_, layout.width);
  ASSERT_EQ(image.height_, layout.height);
  for (int v = 0; v < 2; ++v) {
    SCOPED_TRACE("view " + std::to_string(v));
    const Pixels observed = InView(image, layout, 0, v, Provenance::kObserved);
    const Pixels surface = InView(image, layout, 0, v, Provenance::kSurface);
    const Pixels symmetry = InView(image, layout, 0, v, Provenance::kSymmetry);
    EXPECT_GT(observed.count, 1000);
    EXPECT_GT(surface.count, 100);
    EXPECT_GT(symmetry.count, 100);
    // The cap on the palm side above the strip at mid-height.
    EXPECT_LT(symmetry.mean_row + 20, surface.mean_row);
  }
}

TEST(ViewCli, TwoCloudsBeforeAndAfterSideBySide) {
  const std::string dir = ScratchDir("e2e_view_two");
  const ObjectCloud after = HeldCylinder();
  io::WriteCloudPly(dir + "/before.ply", ObservedOnly(after));
  io::WriteCloudPly(dir + "/after.ply", after);
  const auto run =
      RunCli("view " + dir + "/before.ply " + dir + "/after.ply -o " + dir + "/ba.png --views 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const open3d::geometry::Image image = ReadPng(dir + "/ba.png");
  view::SheetConfig config;
  config.views = 1;
  const view::SheetLayout layout = view::LayoutSheet(2, config);
  ASSERT_EQ(image.width_, layout.width);
  EXPECT_GT(InView(image, layout, 0, 0, Provenance::kObserved).count, 1000);
  EXPECT_EQ(InView(image, layout, 0, 0, Provenance::kSurface).count, 0);
  EXPECT_EQ(InView(image, layout, 0, 0, Provenance::kSymmetry).count, 0);
  EXPECT_GT(InView(image, layout, 1, 0, Provenance::kSurface).count, 100);
  EXPECT_GT(InView(image, layout, 1, 0, Provenance::kSymmetry).count, 100);
}

// A closed cube of 8 vertices and 12 triangles: drawn as a surface, it
// covers its whole outline; as 8 points it would cover 8 discs.
TEST(ViewCli, AMeshIsDrawnAsASurface) {
  const std::string dir = ScratchDir("e2e_view_mesh");
  TriangleMesh cube;
  for (int i = 0; i < 8; ++i) {
    cube.vertices.emplace_back(i & 1 ? 0.025f : -0.025f, i & 2 ? 0.025f : -0.025f, i & 4 ? 0.05f : 0.0f);
  }
  cube.triangles = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                    {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  io::WriteMeshPly(dir + "/cube.ply", cube);
  const auto run = RunCli("view " + dir + "/cube.ply -o " + dir + "/cube.png --views 1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const open3d::geometry::Image image = ReadPng(dir + "/cube.png");
  view::SheetConfig config;
  config.views = 1;
  const view::SheetLayout layout = view::LayoutSheet(1, config);
  // Its diagonal spans 0.92 of the view's edge: an edge of 191 of 360
  // pixels; seen from 30 degrees up its front and top faces cover ~50k of
  // 130k pixels (8 points would cover 8 discs, < 2k).
  const int covered = InView(image, layout, 0, 0, Provenance::kObserved).count;
  EXPECT_GT(covered, layout.view_px * layout.view_px / 4) << covered;
  const int c = layout.view_px / 2;
  const uint8_t* centre =
      &image.data_[(static_cast<size_t>(layout.ViewY(0) + c) * image.width_ + layout.ViewX(0) + c) * 3];
  EXPECT_TRUE(IsShadeOf(centre, ProvenanceColor(Provenance::kObserved)));
}

TEST(ViewCli, BadInputIsNamedAndNothingIsOverwritten) {
  const std::string dir = ScratchDir("e2e_view_bad");
  io::WriteCloudPly(dir + "/cloud.ply", HeldCylinder());
  const std::string cloud = dir + "/cloud.ply";

  auto missing = RunCli("view " + dir + "/nope.ply -o " + dir + "/v.png");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find(dir + "/nope.ply"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(dir + "/v.png"));

  auto no_output = RunCli("view " + cloud);
  EXPECT_EQ(no_output.exit_code, 2) << no_output.output;
  EXPECT_NE(no_output.output.find("-o"), std::string::npos) << no_output.output;

  auto zero_views = RunCli("view " + cloud + " -o " + dir + "/v.png --views 0");
  EXPECT_EQ(zero_views.exit_code, 2) << zero_views.output;
  EXPECT_NE(zero_views.output.find("--views '0'"), std::string::npos) << zero_views.output;

  auto not_png = RunCli("view " + cloud + " -o " + dir + "/v.jpg");
  EXPECT_EQ(not_png.exit_code, 2) << not_png.output;

  auto no_dir = RunCli("view " + cloud + " -o " + dir + "/no/such/dir/v.png");
  EXPECT_EQ(no_dir.exit_code, 1) << no_dir.output;
  EXPECT_NE(no_dir.output.find(dir + "/no/such/dir/v.png"), std::string::npos) << no_dir.output;

  // A folder where the picture should be, or a file where its folder should be.
  fs::create_directories(dir + "/taken.png");
  auto is_dir = RunCli("view " + cloud + " -o " + dir + "/taken.png --force");
  EXPECT_EQ(is_dir.exit_code, 1) << is_dir.output;
  EXPECT_NE(is_dir.output.find(dir + "/taken.png"), std::string::npos) << is_dir.output;
  auto under_file = RunCli("view " + cloud + " -o " + cloud + "/v.png");
  EXPECT_EQ(under_file.exit_code, 1) << under_file.output;
  EXPECT_NE(under_file.output.find(cloud + "/v.png"), std::string::npos) << under_file.output;

  const auto not_a_cloud = RunCli("view " + dir + " -o " + dir + "/v.png");
  EXPECT_EQ(not_a_cloud.exit_code, 1) << not_a_cloud.output;
  EXPECT_NE(not_a_cloud.output.find(dir), std::string::npos) << not_a_cloud.output;

  // An existing picture is kept without --force, replaced with it.
  std::ofstream(dir + "/keep.png") << "mine";
  auto existing = RunCli("view " + cloud + " -o " + dir + "/keep.png");
  EXPECT_EQ(existing.exit_code, 1) << existing.output;
  EXPECT_NE(existing.output.find("--force"), std::string::npos) << existing.output;
  EXPECT_EQ(ReadFile(dir + "/keep.png"), "mine");
  auto forced = RunCli("view " + cloud + " -o " + dir + "/keep.png --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_EQ(ReadFile(dir + "/keep.png").substr(1, 3), "PNG");

  if (geteuid() != 0) {  // root writes anywhere
    fs::create_directories(dir + "/ro");
    chmod((dir + "/ro").c_str(), 0555);
    auto read_only = RunCli("view " + cloud + " -o " + dir + "/ro/v.png");
    EXPECT_EQ(read_only.exit_code, 1) << read_only.output;
    EXPECT_NE(read_only.output.find(dir + "/ro/v.png"), std::string::npos) << read_only.output;
    chmod((dir + "/ro").c_str(), 0755);
  }
}

TEST(ViewCli, SameCloudGivesTheSamePicture) {
  const std::string dir = ScratchDir("e2e_view_same");
  io::WriteCloudPly(dir + "/cloud.ply", HeldCylinder());
  ASSERT_EQ(RunCli("view " + dir + "/cloud.ply -o " + dir + "/a.png").exit_code, 0);
  ASSERT_EQ(RunCli("view " + dir + "/cloud.ply -o " + dir + "/b.png").exit_code, 0);
  EXPECT_EQ(ReadFile(dir + "/a.png"), ReadFile(dir + "/b.png"));
}

TEST(ViewCli, RepairPreviewShowsBeforeAndAfter) {
  const std::string dir = ScratchDir("e2e_view_repair_preview");
  ASSERT_EQ(RunCli("synth --protocol paper --shape cylinder --points 20000 -o " + dir).exit_code, 0);
  const auto run =
      RunCli("repair " + dir + "/holey.ply -o " + dir + "/repaired.ply --preview " + dir + "/pictures");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string preview = dir + "/pictures/repaired.png";
  ASSERT_TRUE(fs::exists(preview)) << run.output;
  const open3d::geometry::Image image = ReadPng(preview);
  const view::SheetLayout layout = view::LayoutSheet(2, view::SheetConfig{});
  ASSERT_EQ(image.width_, layout.width);
  int before_fill = 0, after_fill = 0;
  for (int v = 0; v < layout.views; ++v) {
    for (const Provenance p : {Provenance::kSurface, Provenance::kSymmetry}) {
      before_fill += InView(image, layout, 0, v, p).count;
      after_fill += InView(image, layout, 1, v, p).count;
    }
  }
  EXPECT_EQ(before_fill, 0);
  EXPECT_GT(after_fill, 500);
  // A second run does not replace the preview without --force.
  const auto again =
      RunCli("repair " + dir + "/holey.ply -o " + dir + "/other.ply --preview " + dir + "/pictures");
  EXPECT_EQ(again.exit_code, 0) << again.output;  // other.png: a new name
  fs::create_directories(dir + "/x");
  const auto clash =
      RunCli("repair " + dir + "/holey.ply -o " + dir + "/x/repaired.ply --preview " + dir + "/pictures");
  EXPECT_NE(clash.exit_code, 0) << clash.output;
  EXPECT_NE(clash.output.find("--force"), std::string::npos) << clash.output;
  EXPECT_NE(clash.output.find(preview), std::string::npos) << clash.output;
  EXPECT_FALSE(fs::exists(dir + "/x/repaired.ply"));  // refused before the work
}

TEST(MannersCli, VersionIsTheProjectVersion) {
  const auto run = RunCli("--version");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_EQ(run.output, "graspfill " GRASPFILL_PROJECT_VERSION "\n");
}

// A small recording, replayed with a preview while its output is piped:
// no progress line in the pipe, the version in scene.json and the PLY.
TEST(MannersCli, PipedReplayHasNoProgressAndCarriesTheVersion) {
  const std::string dir = ScratchDir("e2e_manners_replay");
  const auto synth = RunCli("synth --shape cylinder --frames 24 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  EXPECT_EQ(synth.output.find('\r'), std::string::npos) << synth.output;
  const nlohmann::json scene = nlohmann::json::parse(ReadFile(dir + "/scene.json"));
  EXPECT_EQ(scene["software_version"], "graspfill " GRASPFILL_PROJECT_VERSION);

  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + dir +
                             "/cloud.ply --no-publish "
                             "--preview " +
                             dir + "/preview --json");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_EQ(replay.output.find('\r'), std::string::npos) << replay.output;
  EXPECT_EQ(replay.output.find("frames/s"), std::string::npos) << replay.output;
  const nlohmann::json report = nlohmann::json::parse(replay.output.substr(replay.output.find('{')));
  EXPECT_EQ(report["software_version"], "graspfill " GRASPFILL_PROJECT_VERSION);
  EXPECT_EQ(report["preview"], dir + "/preview/cloud.png");
  EXPECT_TRUE(fs::exists(dir + "/preview/cloud.png"));
  const std::string ply = ReadFile(dir + "/cloud.ply");
  EXPECT_NE(ply.substr(0, ply.find("end_header"))
                .find("comment graspfill software graspfill " GRASPFILL_PROJECT_VERSION "\n"),
            std::string::npos);
}

// Runs `graspfill <args>` with a terminal for its stdout and stderr
// (script(1)'s pseudo-terminal): what the terminal showed.
testing::CliResult RunOnTerminal(const std::string& args) {
  return testing::RunShell("LCM_DEFAULT_URL=memq:// script -qec '" GRASPFILL_CLI " " + args +
                           "' /dev/null </dev/null");
}

// On a terminal the progress line shows (its first state is always drawn)
// and is erased at the end; --quiet turns it off.
TEST(MannersCli, ProgressOnATerminalOnly) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const std::string dir = ScratchDir("e2e_manners_tty");
  const std::string synth = "synth --shape cylinder --frames 12 --force -o " + dir;
  const auto shown = RunOnTerminal(synth);
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("\rsynth: 1/12 frames"), std::string::npos) << shown.output;
  EXPECT_NE(shown.output.find("\r\033[K"), std::string::npos) << shown.output;
  const auto quiet = RunOnTerminal(synth + " --quiet");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("/12 frames"), std::string::npos) << quiet.output;
  EXPECT_EQ(quiet.output.find("\033[K"), std::string::npos) << quiet.output;
  // The same through a pipe: not a trace of it.
  const auto piped = RunCli(synth);
  ASSERT_EQ(piped.exit_code, 0) << piped.output;
  EXPECT_EQ(piped.output.find("/12 frames"), std::string::npos) << piped.output;
  EXPECT_EQ(piped.output.find('\r'), std::string::npos) << piped.output;
}

// Piped stdout is line-buffered: `bench repair` prints each table row
// when its case is done, so the rows reach the pipe seconds apart (fully
// buffered, all would come at once, when the process exits).
TEST(MannersCli, PipedStdoutIsLineBuffered) {
  using Clock = std::chrono::steady_clock;
  // Three cases ("cuboid 10x10x20", "7x7x14", "5x5x10"), 0.3-1 s each.
  FILE* pipe = popen(
      "LCM_DEFAULT_URL=memq:// " GRASPFILL_CLI " bench repair --case x --points 20000 2>/dev/null", "r");
  ASSERT_NE(pipe, nullptr);
  std::vector<Clock::time_point> rows;
  char line[1024];
  while (std::fgets(line, sizeof(line), pipe) != nullptr) {
    if (std::string(line).rfind("cuboid ", 0) == 0) rows.push_back(Clock::now());
  }
  const Clock::time_point end = Clock::now();
  EXPECT_EQ(pclose(pipe), 0);
  ASSERT_EQ(rows.size(), 3u);
  // Two cases' work between the first row and the end.
  EXPECT_GT(std::chrono::duration<double>(end - rows.front()).count(), 0.25);
}

}  // namespace
}  // namespace graspfill
