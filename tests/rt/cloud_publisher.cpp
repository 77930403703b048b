// SPDX-License-Identifier: BSD-3-Clause
// Test tool: publishes a deterministic object cloud with LcmPublisher and
// prints the "points=<n> checksum=<hex>" a subscriber should report.
// usage: cloud_publisher <lcm-url> <channel> <num-points> <seed> [repeats]
// It publishes `repeats` times (default 20) 50 ms apart, so that a
// subscriber still joining the group gets a copy.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "sinks/lcm_publisher.hpp"
#include "test_cloud.hpp"

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr,
                 "usage: %s <lcm-url> <channel> <num-points> <seed> "
                 "[repeats]\n",
                 argv[0]);
    return 1;
  }
  const std::string url = argv[1];
  const std::string channel = argv[2];
  const int num_points = std::atoi(argv[3]);
  const auto seed = static_cast<uint32_t>(std::strtoul(argv[4], nullptr, 10));
  const int repeats = argc == 6 ? std::atoi(argv[5]) : 20;
  if (!graspfill::rt::testing::UrlAllowed(url)) return 1;
  try {
    graspfill::rt::LcmPublisher publisher(url);
    const graspfill::ObjectCloud cloud = graspfill::rt::testing::MakeTestCloud(num_points, seed);
    // What the subscriber must report: the cloud as the wire carries it.
    std::printf("%s\n",
                graspfill::rt::testing::SummaryLine(graspfill::rt::testing::AsOnTheWire(cloud)).c_str());
    std::fflush(stdout);
    for (int i = 0; i < repeats; ++i) {
      if (!publisher.PublishCloud(channel, cloud)) {
        std::fprintf(stderr, "cloud_publisher: publish failed\n");
        return 2;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cloud_publisher: %s\n", e.what());
    return 2;
  }
  return 0;
}
