// SPDX-License-Identifier: BSD-3-Clause
// The CLI's shared option helpers: strict numbers (rt/cli/number_parsing.hpp),
// the claw of a session description (rt/cli/claw_option.hpp) and the
// suggestion for a mistyped option (rt/cli/unknown_option.hpp).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>

#include "claw_option.hpp"
#include "error_text.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

// The message a parse throws, "" if it does not.
template <typename F>
std::string UsageMessage(F&& parse) {
  try {
    parse();
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(StrictNumbers, AcceptsWholeNumbersInRange) {
  EXPECT_EQ(ParseDouble("--voxel-m", "0.002", kMinVoxelM, kMaxVoxelM, "m"), 0.002);
  EXPECT_EQ(ParseDouble("--voxel-m", "1e-3", kMinVoxelM, kMaxVoxelM, "m"), 0.001);
  EXPECT_EQ(ParseDouble("--x", "-2.5", -3.0, 0.0), -2.5);
  EXPECT_EQ(ParseDouble("--x", "0.01", 0.0, 0.01), 0.01);  // bounds included
  EXPECT_EQ(ParseInteger<int>("--n", "-7", -10, 10), -7);
  EXPECT_EQ(ParseInteger<int>("--n", "100000", 0, 100000), 100000);
  EXPECT_EQ(ParseInteger<uint64_t>("--seed", "18446744073709551615", 0, std::numeric_limits<uint64_t>::max()),
            std::numeric_limits<uint64_t>::max());
}

TEST(StrictNumbers, RejectsGarbageNamingTheOptionAndTheText) {
  auto d = [](const std::string& text) {
    return UsageMessage([&] { ParseDouble("--voxel-m", text, kMinVoxelM, kMaxVoxelM, "m"); });
  };
  for (const char* text : {"abc", "", " 0.002", "0.002 ", "0.002x", "+0.002", "0x1p-9", "2mm", "0,002"}) {
    EXPECT_EQ(d(text), std::string("--voxel-m '") + text + "': not a number") << text;
  }
  for (const char* text : {"1.5", "nan", "inf", "-inf", "1e999", "-0.001", "0", "0.0004"}) {
    EXPECT_EQ(d(text), std::string("--voxel-m '") + text + "': out of range, expected 0.0005..0.01 m")
        << text;
  }
  auto i = [](const std::string& text) {
    return UsageMessage([&] { ParseInteger<int>("--publish-every", text, 0, 100000); });
  };
  for (const char* text : {"x", "", "3.5", "1e3", " 3", "3 ", "+3", "0x10"}) {
    EXPECT_EQ(i(text), std::string("--publish-every '") + text + "': not an integer") << text;
  }
  for (const char* text : {"-1", "100001", "99999999999999999999"}) {
    EXPECT_EQ(i(text), std::string("--publish-every '") + text + "': out of range, expected 0..100000")
        << text;
  }
  EXPECT_EQ(UsageMessage([] { ParseInteger<uint64_t>("--seed", "-3", 0, 10); }),
            "--seed '-3': not an integer");
}

TEST(SessionClaw, ProceduralDimensionsRoundTripExactly) {
  claw::ProceduralClawConfig config;
  config.finger_length_m = 0.1234567890123;
  config.palm_radius_m = 1.0 / 3.0;
  const claw::ProceduralClawConfig back = ParseProceduralClawText(ProceduralClawText(config));
  EXPECT_EQ(back.finger_length_m, config.finger_length_m);
  EXPECT_EQ(back.palm_radius_m, config.palm_radius_m);
  EXPECT_EQ(back.max_opening_m, config.max_opening_m);
}

TEST(SessionClaw, ProceduralDimensionsAreCheckedFieldByField) {
  auto message = [](const std::string& text) {
    try {
      ParseProceduralClawText(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  nlohmann::json j = nlohmann::json::parse(ProceduralClawText({}));
  j.erase("finger_width_m");
  EXPECT_NE(message(j.dump()).find("finger_width_m: missing"), std::string::npos);
  j = nlohmann::json::parse(ProceduralClawText({}));
  j["finger_length_m"] = "long";
  EXPECT_NE(message(j.dump()).find("finger_length_m"), std::string::npos);
  j = nlohmann::json::parse(ProceduralClawText({}));
  j["fingers"] = 4;
  EXPECT_NE(message(j.dump()).find("unknown key 'fingers'"), std::string::npos);
  EXPECT_NE(message("{").find("bad JSON"), std::string::npos);
  EXPECT_NE(message("[]").find("not a JSON object"), std::string::npos);
}

TEST(SessionClaw, BuiltinSessionGivesTheClawAsDescribed) {
  claw::ProceduralClawConfig longer;
  longer.finger_length_m = 0.12;
  io::SessionDescription session;
  DescribeBuiltinClaw("parallel", longer, &session);
  EXPECT_EQ(session.claw_kind, io::SessionClawKind::kBuiltin);
  const claw::ClawModel model = MakeSessionClaw(session);
  EXPECT_TRUE(SameClaw(model, claw::ClawModel::Parallel(longer)));
  EXPECT_FALSE(SameClaw(model, claw::ClawModel::Parallel()));
  EXPECT_EQ(SessionClawLabel(session), "parallel (as recorded: finger_length_m 0.12)");

  DescribeBuiltinClaw("three-finger", {}, &session);
  EXPECT_EQ(SessionClawLabel(session), "three-finger");
  EXPECT_TRUE(SameClaw(MakeSessionClaw(session), claw::ClawModel::ThreeFinger()));
}

TEST(SessionClaw, SameClawTellsTheBuiltinsApart) {
  EXPECT_TRUE(SameClaw(claw::ClawModel::ThreeFinger(), claw::ClawModel::ThreeFinger()));
  EXPECT_TRUE(SameClaw(claw::ClawModel::Parallel(), claw::ClawModel::Parallel()));
  EXPECT_FALSE(SameClaw(claw::ClawModel::ThreeFinger(), claw::ClawModel::Parallel()));
  claw::ProceduralClawConfig wider;
  wider.finger_width_m += 0.001;
  EXPECT_FALSE(SameClaw(claw::ClawModel::ThreeFinger(), claw::ClawModel::ThreeFinger(wider)));
}

TEST(SessionClaw, ClawsThatCannotBeBuiltSaySo) {
  io::SessionDescription session;
  session.claw_kind = io::SessionClawKind::kUrdf;
  session.claw_name = "robotiq";
  session.claw_source = "robotiq.urdf";
  auto message = [&] {
    try {
      MakeSessionClaw(session);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(),
            "the session description's claw URDF 'robotiq' (robotiq.urdf): URDF claw 'robotiq': "
            "no URDF (empty text) (pass --claw SPEC, or --claw-mesh-root DIR for its meshes)");
  session.claw_text =
      "<robot name='robotiq'><link name='palm'><collision><geometry>"
      "<mesh filename='package://robotiq/palm.stl'/></geometry></collision>"
      "</link></robot>";
  session.claw_mesh_root = "/nonexistent/meshes";
  // The recorded root is a hint, not a place to read from (issue 36).
  EXPECT_NE(message().find("link 'palm'"), std::string::npos) << message();
  EXPECT_NE(message().find("none was given"), std::string::npos) << message();
  EXPECT_NE(message().find("it was made with meshes in /nonexistent/meshes"), std::string::npos) << message();
  try {
    MakeSessionClaw(session, "/nonexistent/meshes");  // the local root
    ADD_FAILURE() << "built";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("palm.stl' not found under /nonexistent/meshes"), std::string::npos)
        << e.what();
  }
  DescribeBuiltinClaw("four-finger", {}, &session);
  EXPECT_NE(message().find("unknown built-in claw"), std::string::npos) << message();
  session.claw_kind = io::SessionClawKind::kDescription;
  session.claw_name = "mine";
  session.claw_text = "{\"links\": [{\"name\": \"palm\", \"mesh\": \"palm.stl\"}]}";
  session.claw_mesh_root = "/nonexistent/meshes";
  EXPECT_NE(message().find("description 'mine'"), std::string::npos) << message();
  EXPECT_NE(message().find("palm.stl"), std::string::npos) << message();
}

// Issue 36: a description claw's text went to TMP/dir/<claw_name>.json, so
// a name "../../victim" wrote outside. It is read in memory now, and its
// meshes only under the local mesh root, never the recorded one.
TEST(SessionClaw, ADescriptionClawIsReadInMemoryWithLocalMeshesOnly) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "session_claw_in_memory";
  fs::remove_all(dir);
  fs::create_directories(dir / "a" / "b");
  fs::create_directories(dir / "recorded");
  std::ofstream(dir / "recorded" / "palm.obj")
      << "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.02\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir ? old_tmpdir : "";
  setenv("TMPDIR", (dir / "a" / "b").c_str(), 1);

  io::SessionDescription session;
  session.claw_kind = io::SessionClawKind::kDescription;
  session.claw_name = "../../victim";  // as a decoder of old let through
  session.claw_text = R"({"links": [{"name": "palm", "mesh": "palm.obj"}]})";
  EXPECT_EQ(MakeSessionClaw(session, (dir / "recorded").string()).links().size(), 1u);
  EXPECT_FALSE(fs::exists(dir / "a" / "victim.json"));
  EXPECT_TRUE(fs::is_empty(dir / "a" / "b"));  // nothing written at all

  session.claw_name = "mine";
  session.claw_text = R"({"links": [{"name": "palm", "mesh": "palm.obj"}]})";
  session.claw_mesh_root = (dir / "recorded").string();
  session.claw_source = (dir / "recorded" / "claw.json").string();
  EXPECT_THROW(MakeSessionClaw(session), std::runtime_error);  // no local root
  EXPECT_EQ(MakeSessionClaw(session, (dir / "recorded").string()).links()[0].mesh.triangles.size(), 4u);
  session.claw_text =
      R"({"links": [{"name": "palm", "mesh": ")" + (dir / "recorded" / "palm.obj").string() + R"("}]})";
  EXPECT_THROW(MakeSessionClaw(session, (dir / "recorded").string()), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir / "a" / "b"));
  if (old_tmpdir) {
    setenv("TMPDIR", saved.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  fs::remove_all(dir);
}

// A slip of the keyboard gets the option it meant; a word far from every
// option gets no guess; the options come from the usage text itself.
TEST(UnknownOption, SuggestsTheNearestOptionOfTheUsageText) {
  const std::string usage =
      "usage: graspfill repair IN.ply -o OUT.ply [--mode paper|best] [--up X,Y,Z]\n"
      "  --force    overwrite\n  --mesh-out FILE\n  --json  print JSON\n";
  EXPECT_EQ(OptionsIn(usage),
            (std::vector<std::string>{"--mode", "--up", "--force", "--mesh-out", "--json"}));
  EXPECT_EQ(BadOptionText("--forse", usage), "bad option '--forse' (did you mean --force?)");
  EXPECT_EQ(BadOptionText("--mesh_out", usage), "bad option '--mesh_out' (did you mean --mesh-out?)");
  EXPECT_EQ(BadOptionText("--jsno", usage), "bad option '--jsno' (did you mean --json?)");  // a swap
  EXPECT_EQ(BadOptionText("--mode=best", usage), "bad option '--mode=best' (did you mean --mode?)");
  EXPECT_EQ(BadOptionText("--verbose", usage), "bad option '--verbose'");
  EXPECT_EQ(BadOptionText("--u", usage), "bad option '--u' (did you mean --up?)");
  EXPECT_EQ(BadOptionText("--zz", usage), "bad option '--zz'");  // two of two letters off
  EXPECT_EQ(BadOptionText("extra.ply", usage), "bad argument 'extra.ply'");
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(Nearest("replai", {"repair", "replay"}), "replay");
  EXPECT_EQ(Nearest("xyz", {"repair", "replay"}), "");
}

}  // namespace
}  // namespace graspfill::cli
