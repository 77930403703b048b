// The CLI's shared option helpers: strict numbers (rt/cli/number_parsing.hpp)
// and the claw of a session description (rt/cli/claw_option.hpp).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>

#include "claw_option.hpp"
#include "error_text.hpp"
#include "number_parsing.hpp"

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
  EXPECT_EQ(ParseInteger<uint64_t>("--seed", "18446744073709551615", 0,
                                   std::numeric_limits<uint64_t>::max()),
            std::numeric_limits<uint64_t>::max());
}

TEST(StrictNumbers, RejectsGarbageNamingTheOptionAndTheText) {
  auto d = [](const std::string& text) {
    return UsageMessage([&] { ParseDouble("--voxel-m", text, kMinVoxelM, kMaxVoxelM, "m"); });
  };
  for (const char* text : {"abc", "", " 0.002", "0.002 ", "0.002x", "+0.002", "0x1p-9", "2mm",
                           "0,002"}) {
    EXPECT_EQ(d(text), std::string("--voxel-m '") + text + "': not a number") << text;
  }
  for (const char* text : {"1.5", "nan", "inf", "-inf", "1e999", "-0.001", "0", "0.0004"}) {
    EXPECT_EQ(d(text), std::string("--voxel-m '") + text +
                           "': out of range, expected 0.0005..0.01 m")
        << text;
  }
  auto i = [](const std::string& text) {
    return UsageMessage([&] { ParseInteger<int>("--publish-every", text, 0, 100000); });
  };
  for (const char* text : {"x", "", "3.5", "1e3", " 3", "3 ", "+3", "0x10"}) {
    EXPECT_EQ(i(text), std::string("--publish-every '") + text + "': not an integer") << text;
  }
  for (const char* text : {"-1", "100001", "99999999999999999999"}) {
    EXPECT_EQ(i(text), std::string("--publish-every '") + text +
                           "': out of range, expected 0..100000")
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
  session.claw_text = "<robot name='robotiq'><link name='palm'><collision><geometry>"
                      "<mesh filename='package://robotiq/palm.stl'/></geometry></collision>"
                      "</link></robot>";
  session.claw_mesh_root = "/nonexistent/meshes";
  EXPECT_NE(message().find("link 'palm'"), std::string::npos) << message();
  EXPECT_NE(message().find("palm.stl' not found under /nonexistent/meshes"), std::string::npos)
      << message();
  DescribeBuiltinClaw("four-finger", {}, &session);
  EXPECT_NE(message().find("unknown built-in claw"), std::string::npos) << message();
  session.claw_kind = io::SessionClawKind::kDescription;
  session.claw_name = "mine";
  session.claw_text = "{\"links\": [{\"name\": \"palm\", \"mesh\": \"palm.stl\"}]}";
  session.claw_mesh_root = "/nonexistent/meshes";
  EXPECT_NE(message().find("description 'mine'"), std::string::npos) << message();
  EXPECT_NE(message().find("palm.stl"), std::string::npos) << message();
}

}  // namespace
// Allocation failures reach the user as what happened, not as the
// library's "std::bad_alloc"; every other message is passed on as it is.
TEST(ErrorText, NamesAllocationFailuresInWords) {
  EXPECT_EQ(ErrorText(std::bad_alloc()).find("std::bad_alloc"), std::string::npos);
  EXPECT_NE(ErrorText(std::bad_alloc()).find("out of memory"), std::string::npos);
  const std::string too_long =
      ErrorText(std::length_error("cannot create std::vector larger than max_size()"));
  EXPECT_EQ(too_long.rfind("a size beyond what can be allocated", 0), 0u) << too_long;
  // Named in words: the library's "max_size()" means nothing to the user.
  EXPECT_EQ(too_long.find("max_size"), std::string::npos) << too_long;
  EXPECT_EQ(ErrorText(std::runtime_error("cannot open log 'x'")), "cannot open log 'x'");
}

}  // namespace graspfill::cli
