// SPDX-License-Identifier: BSD-3-Clause
// Writes a copy of a recording with crafted session descriptions in it, the
// kind a careless or hostile publisher puts on the bus, for live's tests of
// bus input (tests/rt/live_bus_faults.sh). Encoded with the generated type,
// not graspfill's encoder, which refuses most of them.
//   traversal NAME  the head description: a description claw named NAME
//                   (e.g. ../../victim), its text a valid claw
//   absolute NAME   the same with an absolute NAME
//   voxel           the head description: parallel, voxel 1 m
//   workspace       the head description: parallel, box +-1e300 m
//   missing_mesh    the head description: a URDF claw whose mesh is missing
//   other_claw      the head description: three-finger (the recording's
//                   claw); three times mid-session one of another claw (the
//                   parallel built-in)
//   urdf_stall      no head description; mid-session a URDF claw of 10,000
//                   links
// usage: session_fault_log IN.lcmlog OUT.lcmlog CASE [NAME]
// The recording's own session description, if any, is left out. Prints the
// depth frames in the output and where the crafted descriptions went:
// "depth N injected_at K1,K2,..." (K: depth frames before it).
#include <cstdio>
#include <graspfill/session_description_t.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace {

using Msg = graspfill::session_description_t;

Msg Base() {
  Msg msg{};
  msg.software_version = "session_fault_log";
  msg.claw_kind = Msg::CLAW_BUILTIN;
  msg.claw_name = "parallel";
  msg.claw_text = R"({"palm_radius_m":0.07,"palm_thickness_m":0.02,"finger_length_m":0.09,)"
                  R"("finger_width_m":0.022,"finger_thickness_m":0.012,"min_opening_m":0.005,)"
                  R"("max_opening_m":0.08})";
  msg.T_C_B_orientation[0] = 1.0;
  return msg;
}

// A star of `links` links, every one on the first by a prismatic joint
// (each actuated joint makes the loader judge its open end over all the
// links: seconds for 10,000).
std::string UrdfText(int links, const std::string& geometry) {
  std::string text = "<?xml version=\"1.0\"?>\n<robot name=\"crafted\">\n";
  for (int i = 0; i < links; ++i) {
    text += "<link name=\"l" + std::to_string(i) + "\"><collision><geometry>" + geometry +
            "</geometry></collision></link>\n";
  }
  for (int i = 1; i < links; ++i) {
    text += "<joint name=\"j" + std::to_string(i) +
            "\" type=\"prismatic\"><parent link=\"l0\"/>"
            "<child link=\"l" +
            std::to_string(i) + "\"/><origin xyz=\"0 0 " + std::to_string(0.00001 * i) +
            "\"/><axis xyz=\"1 0 0\"/><limit lower=\"0\" "
            "upper=\"0.01\" effort=\"1\" velocity=\"1\"/></joint>\n";
  }
  return text + "</robot>\n";
}

std::vector<uint8_t> Encode(const Msg& msg) {
  std::vector<uint8_t> out(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    std::fprintf(stderr, "usage: session_fault_log IN.lcmlog OUT.lcmlog CASE [NAME]\n");
    return 2;
  }
  const std::string kase = argv[3];
  const std::string name = argc == 5 ? argv[4] : "";
  try {
    Msg crafted = Base();
    Msg head = crafted;                 // what goes first
    bool replace_head = true;           // else no description first
    std::vector<double> mid_fractions;  // where mid-session ones go
    if (kase == "traversal" || kase == "absolute") {
      if (name.empty()) throw std::runtime_error(kase + " needs a NAME");
      crafted.claw_kind = Msg::CLAW_DESCRIPTION;
      crafted.claw_name = name;
      crafted.claw_text = R"({"name": "crafted", "links": [{"name": "palm"}]})";
    } else if (kase == "voxel") {
      crafted.voxel_m = 1.0;
    } else if (kase == "workspace") {
      crafted.has_workspace_box = 1;
      for (int k = 0; k < 3; ++k) {
        crafted.workspace_min[k] = -1e300;
        crafted.workspace_max[k] = 1e300;
      }
    } else if (kase == "missing_mesh") {
      crafted.claw_kind = Msg::CLAW_URDF;
      crafted.claw_name = "crafted";
      crafted.claw_text = UrdfText(1, "<mesh filename=\"meshes/missing.stl\"/>");
    } else if (kase == "other_claw") {
      head.claw_name = "three-finger";
      mid_fractions = {0.3, 0.5, 0.7};
    } else if (kase == "urdf_stall") {
      replace_head = false;
      crafted.claw_kind = Msg::CLAW_URDF;
      crafted.claw_name = "crafted";
      crafted.claw_text = UrdfText(10000, "<box size=\"0.001 0.001 0.001\"/>");
      mid_fractions = {0.25};
    } else {
      throw std::runtime_error("unknown case '" + kase + "'");
    }
    if (kase != "other_claw") head = crafted;
    const std::vector<uint8_t> crafted_bytes = Encode(crafted);
    const std::vector<uint8_t> head_bytes = Encode(head);

    const graspfill::io::ChannelNames channels;
    int total_depth = 0;
    {
      graspfill::io::LcmLogReader count(argv[1]);
      graspfill::io::LogEvent event;
      while (count.Next(&event) == graspfill::io::LogReadResult::kEvent) {
        total_depth += event.channel == channels.depth;
      }
    }
    std::vector<int> inject_before;  // depth frame indices
    for (const double f : mid_fractions) inject_before.push_back(static_cast<int>(f * total_depth));

    graspfill::io::LcmLogReader reader(argv[1]);
    graspfill::rt::LcmLogWriter writer(argv[2], true);
    graspfill::io::LogEvent event;
    int depth_seen = 0;
    bool head_done = false;
    std::string injected;
    size_t next = 0;
    while (reader.Next(&event) == graspfill::io::LogReadResult::kEvent) {
      if (event.channel == channels.session) continue;  // the recording's own: replaced
      if (event.channel == channels.depth) {
        if (replace_head && !head_done) {
          writer.Write(channels.session, event.timestamp_us, head_bytes);
          head_done = true;
          injected += "0";
        }
        while (next < inject_before.size() && inject_before[next] == depth_seen) {
          writer.Write(channels.session, event.timestamp_us, crafted_bytes);
          injected += (injected.empty() ? "" : ",") + std::to_string(depth_seen);
          ++next;
        }
        ++depth_seen;
      }
      writer.Write(event.channel, event.timestamp_us, event.data);
    }
    if (!reader.error().empty()) throw std::runtime_error(reader.error());
    writer.Close();
    std::printf("depth %d injected_at %s\n", depth_seen, injected.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "session_fault_log: %s\n", e.what());
    return 1;
  }
  return 0;
}
