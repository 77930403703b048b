#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""tests/rt/cloud_subscriber in Python: waits for one object_cloud_t with
graspfill.Subscriber and prints the line tests/rt/cloud_publisher prints for
what it sent (tests/rt/test_cloud.hpp's SummaryLine: count, checksum,
added, holes). Run by tests/rt/udpm_cloud_roundtrip.sh inside `unshare -n`.

usage: print_cloud_summary.py URL CHANNEL TIMEOUT_MS
Exit: 0 received, 1 refused (udpm outside a private network), 2 nothing
within the timeout.
"""
import fcntl
import socket
import struct
import sys

import numpy as np

import graspfill

SIOCGIFFLAGS = 0x8913
IFF_UP = 0x1
IFF_LOOPBACK = 0x8
FNV_OFFSET = 1469598103934665603
FNV_PRIME = 1099511628211


def fnv1a(data, h):
    for byte in data:
        h = ((h ^ byte) * FNV_PRIME) & 0xFFFFFFFFFFFFFFFF
    return h


def checksum(cloud):
    """test_cloud.hpp's CloudChecksum: seq, points, normals, provenance, holes' added points."""
    h = fnv1a(np.int64(cloud["seq"]).tobytes(), FNV_OFFSET)
    h = fnv1a(cloud["points"].tobytes(), h)
    if cloud["normals"] is not None:
        h = fnv1a(cloud["normals"].tobytes(), h)
    h = fnv1a(cloud["provenance"].tobytes(), h)
    for hole in cloud["holes"]:
        h = fnv1a(np.int32(hole["points_added"]).tobytes(), h)
    return h


def only_loopback_is_up():
    """As test_cloud.hpp's OnlyLoopbackIsUp: inside `unshare -n`, only `lo` is up.
    (Interfaces of this process's network namespace, with their SIOCGIFFLAGS.)"""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        for _, name in socket.if_nameindex():
            request = struct.pack("16sH", name.encode()[:15], 0)
            flags = struct.unpack("16sH", fcntl.ioctl(probe.fileno(), SIOCGIFFLAGS, request)[:18])[1]
            if flags & IFF_UP and not flags & IFF_LOOPBACK:
                return False
    return True


def main():
    url, channel, timeout_s = sys.argv[1], sys.argv[2], float(sys.argv[3]) / 1e3
    if url.startswith("udpm://") and not only_loopback_is_up():
        print(f"refusing {url}: a non-loopback interface is up; run inside `unshare -n`", file=sys.stderr)
        return 1
    with graspfill.Subscriber(channel=channel, url=url) as subscriber:
        cloud = subscriber.next(timeout_s=timeout_s)
    if cloud is None:
        print(f"print_cloud_summary: nothing on {channel} within {timeout_s} s", file=sys.stderr)
        return 2
    added = int(np.count_nonzero(cloud["provenance"]))
    print(f"points={len(cloud['points'])} checksum={checksum(cloud):016x} added={added} "
          f"holes={len(cloud['holes'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
