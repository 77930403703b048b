#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""The added points' normals against the scan's, for two dumps of the same rows.

    scripts/added_normals_error.py BEFORE AFTER

BEFORE and AFTER are folders written by `graspfill bench repair --objects DIR
--dump OUT` with two builds. For each row found in both (NAME_repaired.ply
beside NAME_truth.ply), the added points (provenance not 0) are compared with
the nearest truth sample: the angle between the two normals, unoriented
[deg], median and p95, and the share that points the other way. Needs
graspfill's Python package (the build tree's: PYTHONPATH=build/lcmtypes/
lcmgen/python) and scipy (Debian: python3-scipy).
(docs/measurements/2026-12-07-repair-time-and-ablations.md)
"""
import glob
import os
import sys

try:
    import graspfill
    import numpy as np
    from scipy.spatial import cKDTree
except ImportError as e:
    sys.exit(f"added_normals_error.py: {e} (PYTHONPATH=build/lcmtypes/lcmgen/python; apt-get install python3-scipy)")


def row_error(folder, name):
    """(added points, median deg, p95 deg, share flipped), or None without added points."""
    repaired = graspfill.read_ply(os.path.join(folder, name + "_repaired.ply"))
    truth = graspfill.read_ply(os.path.join(folder, name + "_truth.ply"))
    if repaired["normals"] is None or truth["normals"] is None:
        sys.exit(f"added_normals_error.py: {folder}/{name}: a cloud without normals")
    added = repaired["provenance"] != 0
    if not added.any():
        return None
    _, nearest = cKDTree(truth["points"]).query(repaired["points"][added])
    dot = np.sum(repaired["normals"][added].astype(np.float64) * truth["normals"][nearest], axis=1)
    angle = np.degrees(np.arccos(np.clip(np.abs(dot), 0.0, 1.0)))
    return int(added.sum()), np.median(angle), np.percentile(angle, 95), np.mean(dot < 0.0)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[2].strip().join(["usage: ", ""]))
    before, after = sys.argv[1:]
    names = sorted(
        os.path.basename(p)[: -len("_repaired.ply")] for p in glob.glob(os.path.join(before, "*_repaired.ply"))
    )
    names = [n for n in names if os.path.exists(os.path.join(after, n + "_repaired.ply"))]
    if not names:
        sys.exit("added_normals_error.py: no row dumped in both folders")
    print(f"{'row':55s} {'added':>7s} | before: median p95 [deg] flipped | after: median p95 [deg] flipped")
    for name in names:
        a, b = row_error(before, name), row_error(after, name)
        if a is None or b is None:
            print(f"{name:55s} {'none':>7s}")
            continue
        print(f"{name:55s} {a[0]:7d} | {a[1]:6.1f} {a[2]:6.1f} {a[3]:6.3f} | {b[1]:6.1f} {b[2]:6.1f} {b[3]:6.3f}")


if __name__ == "__main__":
    main()
