#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Repairs an object cloud from a PLY with graspfill's Python module and
writes the result, as `graspfill repair IN.ply -o OUT.ply` does: the input
points first, then the added ones, with their provenance and confidence.

usage: repair_ply.py IN.ply OUT.{ply,pcd} [--up X,Y,Z]
Exit: 0 written; 1 when the cloud could not be repaired as given (another
unit than meters, for one: nothing is written then).
"""
import argparse
import sys

import numpy as np

import graspfill


def main():
    parser = argparse.ArgumentParser(description="Fill the claw holes and the unseen top of a cloud.")
    parser.add_argument("input", help="point cloud PLY in meters")
    parser.add_argument("output", help="repaired cloud, PLY or PCD by its extension")
    parser.add_argument("--up", help="X,Y,Z: optional direction towards the missing top")
    args = parser.parse_args()

    cloud = graspfill.read_ply(args.input)
    up = [float(v) for v in args.up.split(",")] if args.up else None
    points, provenance, confidence, report = graspfill.repair(cloud["points"], cloud["normals"], up=up)
    if report["status"].startswith("outside the repair's limits"):
        print(f"repair_ply: {args.input}: {report['status']} (a cloud in mm? scale it to meters)",
              file=sys.stderr)
        return 1
    graspfill.write_ply(args.output, points, provenance=provenance, confidence=confidence,
                        normals=report.get("normals"))

    print(f"{args.input}: {len(cloud['points'])} points in, {len(points)} out ({report['status']})")
    for hole in report["holes"]:
        print(f"  {hole['kind']:<16} boundary {hole['boundary_points']:4d} points, "
              f"{hole['points_added']:5d} points added")
    print(f"  top: {report['top_completion'] or '-'} (confidence {report['top_confidence']:.2f}), "
          f"added points by provenance (surface, symmetry): {np.bincount(provenance, minlength=3)[1:3].tolist()}")
    print(f"  repair took {sum(report['timings_ms'].values()):.1f} ms -> {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
