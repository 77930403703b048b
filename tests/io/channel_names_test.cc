// SPDX-License-Identifier: BSD-3-Clause
// Channel names as LCM takes them (issue 36): 1..63 characters of
// A-Z a-z 0-9 _ - /, the six distinct; the first problem named with its
// channel.
#include "graspfill/io/channel_names.hpp"

#include <gtest/gtest.h>

#include <string>

namespace graspfill::io {
namespace {

TEST(ChannelNames, TheDefaultsAndEveryAllowedCharacterPass) {
  EXPECT_FALSE(FindChannelNameProblem(ChannelNames{}).has_value());
  for (const std::string& name :
       {std::string("GRASPFILL_DEPTH"), std::string("robot-1/cam_2/depth"),
        std::string("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_"),
        std::string(63, 'x')}) {
    EXPECT_EQ(ChannelNameDefect(name), "") << name;
  }
}

TEST(ChannelNames, RegexCharactersLengthAndEmptinessAreRefused) {
  EXPECT_EQ(ChannelNameDefect(""), "empty");
  EXPECT_EQ(ChannelNameDefect(std::string(64, 'x')), "64 characters, over LCM's limit of 63");
  EXPECT_EQ(ChannelNameDefect(std::string(300, 'x')), "300 characters, over LCM's limit of 63");
  // Each special in a regular expression (LCM subscribes with the name as
  // one), and space, and a byte beyond ASCII.
  for (const char c : std::string(".()[]{}*+?|^$\\ :,;")) {
    const std::string defect = ChannelNameDefect(std::string("A") + c + "B");
    EXPECT_EQ(defect.rfind(std::string("'") + c +
                               "' is not allowed (channel names are A-Z a-z "
                               "0-9 _ - / only",
                           0),
              0u)
        << defect;
  }
  EXPECT_EQ(ChannelNameDefect("A\tB").rfind("byte 0x09 is not allowed", 0), 0u);
  EXPECT_EQ(ChannelNameDefect("caf\xc3\xa9").rfind("byte 0xc3 is not allowed", 0), 0u);
}

TEST(ChannelNames, TheFirstProblemNamesItsChannel) {
  ChannelNames names;
  names.object_cloud = "CLOUD(";
  names.session = std::string(100, 's');
  auto problem = FindChannelNameProblem(names);
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->role, "object_cloud");
  EXPECT_EQ(problem->name, "CLOUD(");
  EXPECT_NE(problem->defect.find("'(' is not allowed"), std::string::npos);
  // Two the same: the later one, with the earlier it repeats.
  names = ChannelNames{};
  names.session = names.gripper_state;
  problem = FindChannelNameProblem(names);
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->role, "session");
  EXPECT_EQ(problem->same_as, "gripper_state");
  EXPECT_EQ(problem->defect, "");
  names = ChannelNames{};
  names.status = names.depth;
  EXPECT_EQ(FindChannelNameProblem(names)->same_as, "depth");
  // The collision mesh's channel is one of them.
  names = ChannelNames{};
  names.collision_mesh = names.object_cloud;
  problem = FindChannelNameProblem(names);
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->role, "collision_mesh");
  EXPECT_EQ(problem->same_as, "object_cloud");
  names = ChannelNames{};
  names.collision_mesh = "MESH*";
  EXPECT_EQ(FindChannelNameProblem(names)->role, "collision_mesh");
}

}  // namespace
}  // namespace graspfill::io
