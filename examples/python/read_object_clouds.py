#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Reads graspfill's object clouds from an LCM log file and prints a summary
of each, as the C++ and Java subscribers do:

  seq=S utime=U grasp=G final=F points=N observed=A surface=B symmetry=C holes=H unobserved=U trusted=T

(T: the added points the repair stands behind, confidence above 0.5.)

Debian ships no Python binding of LCM, and none is needed to read a log: the
event format is small (below), and the classes `lcm-gen -p` made (the
package `graspfill`, installed by graspfill under
PREFIX/lib/python3/dist-packages) decode a message with the `struct` module
alone. The points travel packed (layout in object_cloud_t.lcm); `unpack`
below turns them into plain lists with `zlib` and `array`. A log of a live
bus (lcm-logger on UDP multicast) holds each cloud as one-datagram slices
(object_cloud_chunk_t.lcm); `SliceJoiner` joins them.

usage: read_object_clouds.py LOG [--channel NAME]
Exit: 0 when at least one cloud was read; 1 on a missing, malformed or
truncated log, or a log without clouds on the channel.
"""
import argparse
import array
import struct
import sys
import zlib

from graspfill import object_cloud_chunk_t, object_cloud_t

# One event of an LCM log (all big-endian): sync word, event number, utime
# [us], channel length, data length, then the channel name and the data.
SYNC_WORD = 0xEDA1DA01
EVENT_HEADER = struct.Struct(">Iqqii")


class LogError(Exception):
    pass


def read_events(path):
    """Yields (utime, channel, data) for every event of the log at `path`."""
    with open(path, "rb") as log:
        while True:
            offset = log.tell()
            header = log.read(EVENT_HEADER.size)
            if not header:
                return
            if len(header) < EVENT_HEADER.size:
                raise LogError(f"truncated event header at byte {offset}")
            sync, _, utime, channel_len, data_len = EVENT_HEADER.unpack(header)
            if sync != SYNC_WORD:
                raise LogError(f"no LCM sync word at byte {offset} (not an LCM log?)")
            if channel_len < 0 or data_len < 0:
                raise LogError(f"negative length in the event at byte {offset}")
            channel = log.read(channel_len)
            data = log.read(data_len)
            if len(channel) < channel_len or len(data) < data_len:
                raise LogError(f"truncated event at byte {offset}")
            yield utime, channel.decode("utf-8", "replace"), data


class SliceJoiner:
    """Joins object_cloud_chunk_t slices into whole object_cloud_t bytes, one
    cloud at a time (a slice of another cloud drops an unfinished one);
    whole object_cloud_t messages pass through."""

    def __init__(self):
        self.key, self.parts, self.completed = None, {}, None

    def add(self, data):
        """The whole cloud's bytes, or None while slices are missing (or for
        a repeat); ValueError for a message of another type or a bad slice."""
        if data[:8] == object_cloud_t._get_packed_fingerprint():
            return data
        chunk = object_cloud_chunk_t.decode(data)
        key = (chunk.utime, chunk.seq, chunk.cloud_num_bytes, chunk.cloud_crc32, chunk.num_chunks)
        if not 0 <= chunk.chunk_index < chunk.num_chunks:
            raise ValueError(f"slice {chunk.chunk_index} of {chunk.num_chunks}")
        if key == self.completed:
            return None
        if key != self.key:
            self.key, self.parts = key, {}
        self.parts[chunk.chunk_index] = chunk.data
        if len(self.parts) < chunk.num_chunks:
            return None
        whole = b"".join(self.parts[i] for i in range(chunk.num_chunks))
        self.key, self.parts = None, {}
        if len(whole) != chunk.cloud_num_bytes or zlib.crc32(whole) != chunk.cloud_crc32 & 0xFFFFFFFF:
            raise ValueError("the joined slices do not match their size and CRC-32")
        self.completed = key
        return whole


def unpack(cloud):
    """The cloud's points as lists: xyz (3 per point, meters in the gripper
    frame), normals (3 per point, or none), provenance and confidence."""
    n = cloud.num_points
    raw = zlib.decompress(cloud.packed_points)
    if len(raw) != n * (6 + 3 * cloud.has_normals + 2):
        raise ValueError(f"the packed points inflate to {len(raw)} bytes for {n} points")
    steps = array.array("h", raw[:6 * n])
    if sys.byteorder != "little":
        steps.byteswap()
    xyz = [0.0] * (3 * n)
    for k in range(3):
        origin, step = cloud.origin[k], cloud.step_m
        for i in range(n):
            xyz[3 * i + k] = origin + step * steps[k * n + i]
    at = 6 * n
    normals = []
    if cloud.has_normals:
        unit = array.array("b", raw[at:at + 3 * n])
        normals = [unit[k * n + i] / 127.0 for i in range(n) for k in range(3)]
        at += 3 * n
    provenance = list(raw[at:at + n])
    confidence = [c / 255.0 for c in raw[at + n:at + 2 * n]]
    return xyz, normals, provenance, confidence


def summary(cloud):
    _, _, provenance, confidence = unpack(cloud)
    # Added points more likely right than not; the rest of the added ones
    # (a lid no view saw) are a guess, which the safe bound covers.
    trusted = sum(1 for p, c in zip(provenance, confidence)
                  if p != object_cloud_t.OBSERVED and c > 0.5)
    by_provenance = [0, 0, 0]
    for p in provenance:
        if 0 <= p < 3:
            by_provenance[p] += 1
    return (f"seq={cloud.seq} utime={cloud.utime} grasp={cloud.grasp_id} "
            f"final={cloud.is_final} points={cloud.num_points} "
            f"observed={by_provenance[object_cloud_t.OBSERVED]} "
            f"surface={by_provenance[object_cloud_t.SURFACE]} "
            f"symmetry={by_provenance[object_cloud_t.SYMMETRY]} holes={cloud.num_holes} "
            # Holes whose inside nothing is known of (an open mouth): keep clear.
            f"unobserved={sum(1 for h in cloud.holes if h.unobserved)} trusted={trusted}")


def main():
    parser = argparse.ArgumentParser(description="Summarize graspfill object clouds in an LCM log.")
    parser.add_argument("log", help="LCM log file (lcm-logger, or graspfill with --lcm-url file://LOG?mode=w)")
    parser.add_argument("--channel", default="GRASPFILL_OBJECT_CLOUD")
    args = parser.parse_args()
    clouds = 0
    joiner = SliceJoiner()
    try:
        for utime, channel, data in read_events(args.log):
            if channel != args.channel:
                continue
            try:
                whole = joiner.add(data)
                if whole is None:  # a slice of a cloud still missing some
                    continue
                cloud = object_cloud_t.decode(whole)
                line = summary(cloud)
            except (ValueError, struct.error, zlib.error) as e:  # another type, or cut short
                print(f"read_object_clouds: skipping the event at utime {utime}: {e}", file=sys.stderr)
                continue
            print(line)
            clouds += 1
    except (OSError, LogError) as e:
        print(f"read_object_clouds: {args.log}: {e}", file=sys.stderr)
        return 1
    if clouds == 0:
        print(f"read_object_clouds: no object_cloud_t on {args.channel} in {args.log}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
