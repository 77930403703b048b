#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Prints one line per object cloud graspfill publishes, received live with
graspfill's Python module (graspfill.Subscriber, over liblcm's C API: no
Python LCM binding needed), as the C++ and Java subscribers do:

  seq=S utime=U grasp=G final=F points=N observed=A surface=B symmetry=C holes=H unobserved=U trusted=T

(T: the added points the repair stands behind, confidence above 0.5.)

usage: subscribe_clouds.py [URL] [--channel NAME] [--count N] [--timeout-s S]
  URL  LCM URL (default: LCM's default; a recorded bus log plays as
       'file://LOG?speed=0'). On UDP multicast each cloud comes as
       one-datagram slices, which graspfill.Subscriber joins: LCM's default
       receive buffer is enough (docs/planner-bindings.md).
Exit: 0 once --count clouds were printed (default: runs until Ctrl-C, or a
log's end); 1 when --timeout-s passed without the next cloud, or LCM ended
before --count clouds.
"""
import argparse
import sys

import numpy as np

import graspfill


def summary(cloud):
    observed, surface, symmetry = np.bincount(cloud["provenance"], minlength=3)[:3]
    unobserved = sum(1 for hole in cloud["holes"] if hole["unobserved"])  # keep clear of these
    # Added points more likely right than not; the rest of the added ones
    # (a lid no view saw) are a guess, which the safe bound covers.
    added = np.asarray(cloud["provenance"]) != 0
    trusted = int(np.count_nonzero(added & (np.asarray(cloud["confidence"]) > 0.5)))
    return (f"seq={cloud['seq']} utime={cloud['utime']} grasp={cloud['grasp_id']} "
            f"final={int(cloud['is_final'])} points={len(cloud['points'])} observed={observed} "
            f"surface={surface} symmetry={symmetry} holes={len(cloud['holes'])} unobserved={unobserved} "
            f"trusted={trusted}")


def main():
    parser = argparse.ArgumentParser(description="Print graspfill's object clouds as they arrive.")
    parser.add_argument("url", nargs="?", default="", help="LCM URL (default: LCM's default)")
    parser.add_argument("--channel", default="GRASPFILL_OBJECT_CLOUD")
    parser.add_argument("--count", type=int, default=0, help="stop after N clouds (0: never)")
    parser.add_argument("--timeout-s", type=float, default=None, help="give up after S s without a cloud")
    args = parser.parse_args()
    received = 0
    with graspfill.Subscriber(channel=args.channel, url=args.url) as subscriber:
        while args.count == 0 or received < args.count:
            try:
                cloud = subscriber.next(timeout_s=args.timeout_s)
            except EOFError:  # a file:// log's end, or the bus failed
                print(f"subscribe_clouds: {received} clouds, then LCM ended", file=sys.stderr)
                return 0 if args.count == 0 else 1
            if cloud is None:
                print(f"subscribe_clouds: no cloud on {args.channel} within {args.timeout_s} s "
                      f"({received} received)", file=sys.stderr)
                return 1
            print(summary(cloud), flush=True)
            received += 1
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
