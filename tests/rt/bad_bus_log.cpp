// SPDX-License-Identifier: BSD-3-Clause
// Writes a copy of a recording in which some messages are damaged the way
// a real bus damages them, for live's per-reason bad-message counts:
// every 10th depth image cycles through a flipped bit in its type hash
// (malformed), fx = fy = 1e-300 (bad_intrinsics) and its last 100 bytes cut
// (malformed); every 20th gripper state gets the quaternion (2, 0, 0, 0)
// (bad_pose). Prints what it damaged as "malformed N bad_intrinsics N
// bad_pose N".
// usage: bad_bus_log IN.lcmlog OUT.lcmlog
#include <cstdio>
#include <exception>
#include <graspfill/depth_image_t.hpp>
#include <graspfill/gripper_state_t.hpp>
#include <graspfill/gripper_state_v1_t.hpp>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "sinks/lcm_log_writer.hpp"

namespace {

template <typename Message>
bool Decode(const std::vector<uint8_t>& data, Message* msg) {
  return msg->decode(data.data(), 0, static_cast<int>(data.size())) == static_cast<int>(data.size());
}

template <typename Message>
std::vector<uint8_t> Encode(const Message& msg) {
  std::vector<uint8_t> out(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

void SpoilQuaternion(double* wxyz) {
  wxyz[0] = 2.0;
  wxyz[1] = wxyz[2] = wxyz[3] = 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bad_bus_log IN.lcmlog OUT.lcmlog\n");
    return 2;
  }
  try {
    const graspfill::io::ChannelNames channels;
    graspfill::io::LcmLogReader reader(argv[1]);
    graspfill::rt::LcmLogWriter writer(argv[2], true);
    int depth_seen = 0, states_seen = 0;
    int malformed = 0, bad_intrinsics = 0, bad_pose = 0;
    graspfill::io::LogEvent event;
    while (reader.Next(&event) == graspfill::io::LogReadResult::kEvent) {
      std::vector<uint8_t> data = event.data;
      if (event.channel == channels.depth && ++depth_seen % 10 == 0) {
        switch ((depth_seen / 10) % 3) {
          case 0:
            data[3] ^= 0x10;  // the type hash
            ++malformed;
            break;
          case 1: {
            graspfill::depth_image_t msg;
            if (!Decode(data, &msg)) throw std::runtime_error("a depth image did not decode");
            msg.fx = msg.fy = 1e-300;
            data = Encode(msg);
            ++bad_intrinsics;
            break;
          }
          default:
            data.resize(data.size() - 100);
            ++malformed;
        }
      } else if (event.channel == channels.gripper_state && ++states_seen % 20 == 0) {
        // Recordings made before grasp ids carry the older layout.
        graspfill::gripper_state_t msg;
        graspfill::gripper_state_v1_t msg_v1;
        if (Decode(data, &msg)) {
          SpoilQuaternion(msg.orientation);
          data = Encode(msg);
        } else if (Decode(data, &msg_v1)) {
          SpoilQuaternion(msg_v1.orientation);
          data = Encode(msg_v1);
        } else {
          throw std::runtime_error("a gripper state did not decode");
        }
        ++bad_pose;
      }
      writer.Write(event.channel, event.timestamp_us, data);
    }
    if (!reader.error().empty()) throw std::runtime_error(reader.error());
    writer.Close();
    std::printf("malformed %d bad_intrinsics %d bad_pose %d\n", malformed, bad_intrinsics, bad_pose);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bad_bus_log: %s\n", e.what());
    return 1;
  }
  return 0;
}
