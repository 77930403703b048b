// SPDX-License-Identifier: BSD-3-Clause
#include "private_network.hpp"

#include <arpa/inet.h>
#include <net/if.h>
#include <net/route.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace graspfill::cli {

namespace {

std::string Errno(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

void SetAddress(sockaddr* out, const char* dotted) {
  sockaddr_in in{};
  in.sin_family = AF_INET;
  inet_pton(AF_INET, dotted, &in.sin_addr);
  std::memcpy(out, &in, sizeof(in));
}

}  // namespace

std::string EnterPrivateNetwork() {
  if (unshare(CLONE_NEWNET) != 0) return Errno("cannot create a network namespace (unshare)");
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return Errno("socket");
  std::string error;
  // Loopback up: a new namespace starts with it down.
  ifreq lo{};
  std::strncpy(lo.ifr_name, "lo", IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFFLAGS, &lo) != 0) {
    error = Errno("cannot read loopback's flags");
  } else {
    lo.ifr_flags = static_cast<short>(lo.ifr_flags | IFF_UP | IFF_RUNNING);
    if (ioctl(fd, SIOCSIFFLAGS, &lo) != 0) error = Errno("cannot bring loopback up");
  }
  // 224.0.0.0/4 via lo: LCM's multicast group goes there.
  if (error.empty()) {
    rtentry route{};
    SetAddress(&route.rt_dst, "224.0.0.0");
    SetAddress(&route.rt_genmask, "240.0.0.0");
    SetAddress(&route.rt_gateway, "0.0.0.0");
    route.rt_flags = RTF_UP;
    char dev[] = "lo";
    route.rt_dev = dev;
    if (ioctl(fd, SIOCADDRT, &route) != 0 && errno != EEXIST) {
      error = Errno("cannot add the multicast route on loopback");
    }
  }
  close(fd);
  return error;
}

}  // namespace graspfill::cli
