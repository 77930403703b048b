// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/channel_names.hpp"

#include <utility>
#include <vector>

namespace graspfill::io {
namespace {

bool Allowed(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
         c == '/';
}

std::string Printable(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
  constexpr char kHex[] = "0123456789abcdef";
  return std::string("byte 0x") + kHex[u >> 4] + kHex[u & 15];
}

}  // namespace

std::string ChannelNameDefect(const std::string& name) {
  if (name.empty()) return "empty";
  if (name.size() > kMaxChannelNameLength) {
    return std::to_string(name.size()) + " characters, over LCM's limit of " +
           std::to_string(kMaxChannelNameLength);
  }
  for (const char c : name) {
    if (!Allowed(c)) {
      return Printable(c) +
             " is not allowed (channel names are A-Z a-z 0-9 _ - / only: LCM subscribes to a "
             "name as a regular expression)";
    }
  }
  return "";
}

std::optional<ChannelNameProblem> FindChannelNameProblem(const ChannelNames& names) {
  const std::vector<std::pair<const char*, const std::string*>> roles = {
      {"depth", &names.depth},
      {"gripper_state", &names.gripper_state},
      {"object_cloud", &names.object_cloud},
      {"status", &names.status},
      {"session", &names.session},
      {"collision_mesh", &names.collision_mesh}};
  for (const auto& [role, name] : roles) {
    if (std::string defect = ChannelNameDefect(*name); !defect.empty()) {
      return ChannelNameProblem{role, *name, std::move(defect), ""};
    }
  }
  for (size_t i = 0; i < roles.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (*roles[i].second == *roles[j].second) {
        return ChannelNameProblem{roles[i].first, *roles[i].second, "", roles[j].first};
      }
    }
  }
  return std::nullopt;
}

}  // namespace graspfill::io
