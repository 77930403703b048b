// SPDX-License-Identifier: BSD-3-Clause
// A deterministic test cloud and a checksum over its content, shared by the
// rt tests and the cross-process publisher/subscriber pair, and the guard
// that keeps the latter off the host network.
#pragma once

#include <ifaddrs.h>
#include <net/if.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt::testing {

/// `num_points` points with normals and mixed provenance, one hole and one
/// timing, all drawn from a fixed-seed generator.
inline ObjectCloud MakeTestCloud(int num_points, uint32_t seed) {
  ObjectCloud cloud;
  cloud.utime = 1700000000000000 + seed;
  cloud.seq = seed;
  cloud.T_C_G.translation() = Eigen::Vector3d(0.05, -0.02, 0.7);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-0.08f, 0.08f);
  for (int i = 0; i < num_points; ++i) {
    cloud.points_G.emplace_back(coord(rng), coord(rng), coord(rng));
    cloud.normals_G.push_back(cloud.points_G.back().normalized());
    cloud.provenance.push_back(static_cast<Provenance>(rng() % 3));
  }
  HoleSummary hole;
  hole.kind = HoleKind::kMissingSurface;
  hole.boundary_points = 12;
  hole.points_added = num_points / 10;
  cloud.holes.push_back(hole);
  cloud.timings.push_back({"fusion", 3.25});
  return cloud;
}

/// `cloud` as a subscriber decodes it: object_cloud_t packs the points
/// (50 um steps, 8-bit normals), so this is what a round trip must give
/// bit for bit.
inline ObjectCloud AsOnTheWire(const ObjectCloud& cloud) {
  const std::vector<uint8_t> bytes = io::EncodeObjectCloud(cloud);
  ObjectCloud decoded;
  std::string error;
  if (!io::DecodeObjectCloud(bytes.data(), bytes.size(), &decoded, &error)) {
    std::fprintf(stderr, "AsOnTheWire: %s\n", error.c_str());
    std::abort();
  }
  return decoded;
}

/// FNV-1a over seq, point and normal bits, provenance and hole counts.
inline uint64_t CloudChecksum(const ObjectCloud& cloud) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  mix(&cloud.seq, sizeof(cloud.seq));
  for (const auto& p : cloud.points_G) mix(p.data(), 3 * sizeof(float));
  for (const auto& n : cloud.normals_G) mix(n.data(), 3 * sizeof(float));
  for (Provenance p : cloud.provenance) mix(&p, 1);
  for (const auto& hole : cloud.holes) mix(&hole.points_added, sizeof(int));
  return h;
}

/// The line the udpm test compares: point count and checksum.
inline std::string SummaryLine(const ObjectCloud& cloud) {
  size_t added = 0;  // points the repair added (provenance not observed)
  for (const Provenance p : cloud.provenance) added += p != Provenance::kObserved;
  char line[128];
  std::snprintf(line, sizeof(line), "points=%zu checksum=%016llx added=%zu holes=%zu", cloud.size(),
                static_cast<unsigned long long>(CloudChecksum(cloud)), added, cloud.holes.size());
  return line;
}

/// True when every network interface that is up is a loopback, as inside
/// `unshare -n` (only `lo`): multicast sent here cannot leave the machine's
/// namespace. (Comparing with PID 1's namespace is not enough: in some
/// sandboxes the shell already runs in a namespace of its own that still
/// has a real interface.)
inline bool OnlyLoopbackIsUp() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool only_loopback = true;
  for (const ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
    if ((i->ifa_flags & IFF_UP) && !(i->ifa_flags & IFF_LOOPBACK)) {
      only_loopback = false;
    }
  }
  freeifaddrs(list);
  return only_loopback;
}

/// Refuses multicast URLs unless only loopback interfaces are up.
inline bool UrlAllowed(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0) return true;
  if (OnlyLoopbackIsUp()) return true;
  std::fprintf(stderr,
               "refusing %s: a non-loopback interface is up; run inside "
               "`unshare -n` (test traffic must not reach the host network)\n",
               url.c_str());
  return false;
}

}  // namespace graspfill::rt::testing
