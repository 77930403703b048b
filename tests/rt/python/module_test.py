#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""The Python module (rt/python) from /usr/bin/python3, against the CLI and
graspfill's own C++ files and messages:

  RepairTest     repair() of a numpy cloud equals `graspfill repair`'s output
                 to the byte (examples/python/repair_ply.py too), and bad
                 arrays raise ValueError
  PlyTest        write_ply() / read_ply() round trip, and their refusals
  BusTest        decode_object_cloud() and Subscriber on the cloud a replay
                 of the bundled recording published (an LCM log written by
                 LCM's file:// provider: no network)

usage: module_test.py [TestClass]  (tests/rt/python/CMakeLists.txt sets
PYTHONPATH to the build tree's package, GRASPFILL_CLI and GRASPFILL_SOURCE_DIR)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import graspfill

CLI = os.environ["GRASPFILL_CLI"]
SOURCE_DIR = os.environ["GRASPFILL_SOURCE_DIR"]
# The examples' LCM log reader (examples/python/read_object_clouds.py).
sys.path.insert(0, os.path.join(SOURCE_DIR, "examples", "python"))
from read_object_clouds import read_events  # noqa: E402

CHANNEL = "GRASPFILL_OBJECT_CLOUD"


def run_cli(*args):
    result = subprocess.run([CLI, *args], capture_output=True, text=True)
    if result.returncode != 0:
        raise AssertionError(f"graspfill {' '.join(args)} exited {result.returncode}:\n"
                             f"{result.stdout}{result.stderr}")
    return result.stdout


class ScratchDirTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix=f"graspfill_python_{cls.__name__}_")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)


class RepairTest(ScratchDirTest):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        run_cli("synth", "--protocol", "paper", "--shape", "cylinder", "--points", "20000", "-o", cls.dir)
        cls.holey_path = os.path.join(cls.dir, "holey.ply")
        cls.cli_path = os.path.join(cls.dir, "cli.ply")
        run_cli("repair", cls.holey_path, "-o", cls.cli_path)
        # The same cloud with normals (radial, as a cylinder's): they are
        # kept, and the added points get estimated ones.
        holey = graspfill.read_ply(cls.holey_path)
        radial = holey["points"] - holey["points"].mean(axis=0)
        radial[:, 2] = 0.0
        cls.normals = (radial / np.linalg.norm(radial, axis=1, keepdims=True)).astype(np.float32)
        cls.holey_normals_path = os.path.join(cls.dir, "holey_normals.ply")
        graspfill.write_ply(cls.holey_normals_path, holey["points"], normals=cls.normals)
        cls.cli_normals_path = os.path.join(cls.dir, "cli_normals.ply")
        run_cli("repair", cls.holey_normals_path, "-o", cls.cli_normals_path)

    def test_repair_equals_the_cli(self):
        holey = graspfill.read_ply(self.holey_path)
        self.assertIsNone(holey["normals"])
        points, provenance, confidence, report = graspfill.repair(holey["points"])
        cli = graspfill.read_ply(self.cli_path)

        self.assertEqual(report["status"], "repaired")
        self.assertGreater(len(report["holes"]), 0)
        self.assertGreater(len(points), len(holey["points"]))
        self.assertEqual(points.dtype, np.float32)
        self.assertEqual(points.shape, cli["points"].shape)
        self.assertEqual(points.tobytes(), cli["points"].tobytes())
        self.assertEqual(provenance.dtype, np.uint8)
        np.testing.assert_array_equal(provenance, cli["provenance"])
        np.testing.assert_array_equal(confidence, cli["confidence"])
        self.assertNotIn("normals", report)  # none given, none made
        # The input comes back first, unchanged and observed.
        n = len(holey["points"])
        self.assertEqual(points[:n].tobytes(), holey["points"].tobytes())
        self.assertTrue(np.all(provenance[:n] == 0))
        self.assertTrue(np.all(provenance[n:] > 0))
        for key in ("top_completion", "top_confidence", "timings_ms"):
            self.assertIn(key, report)
        self.assertGreater(sum(report["timings_ms"].values()), 0.0)

    def test_repair_with_normals_equals_the_cli(self):
        holey = graspfill.read_ply(self.holey_normals_path)
        points, provenance, confidence, report = graspfill.repair(holey["points"], self.normals)
        cli = graspfill.read_ply(self.cli_normals_path)
        self.assertEqual(report["status"], "repaired")
        self.assertEqual(points.tobytes(), cli["points"].tobytes())
        np.testing.assert_array_equal(provenance, cli["provenance"])
        np.testing.assert_array_equal(confidence, cli["confidence"])
        self.assertEqual(report["normals"].shape, points.shape)
        self.assertEqual(report["normals"].tobytes(), cli["normals"].tobytes())
        n = len(holey["points"])
        self.assertEqual(report["normals"][:n].tobytes(), self.normals.tobytes())

    def test_the_example_writes_the_clis_cloud(self):
        out = os.path.join(self.dir, "example.ply")
        result = subprocess.run([sys.executable, os.path.join(SOURCE_DIR, "examples", "python", "repair_ply.py"),
                                 self.holey_path, out], capture_output=True, text=True)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("(repaired)", result.stdout)
        example, cli = graspfill.read_ply(out), graspfill.read_ply(self.cli_path)
        self.assertIsNone(example["normals"])
        for key in ("points", "provenance", "confidence"):
            self.assertEqual(example[key].tobytes(), cli[key].tobytes(), key)

    def test_float64_points_and_an_up_hint_are_taken(self):
        holey = graspfill.read_ply(self.holey_path)
        points, provenance, _, report = graspfill.repair(holey["points"].astype(np.float64), up=[0, 0, 1])
        self.assertEqual(report["status"], "repaired")
        self.assertEqual(points[: len(holey["points"])].tobytes(), holey["points"].tobytes())

    def test_a_cloud_without_holes_comes_back_unchanged(self):
        few = np.zeros((3, 3), np.float32)
        few[:, 0] = [0.0, 0.01, 0.02]
        points, provenance, confidence, report = graspfill.repair(few)
        self.assertEqual(points.tobytes(), few.tobytes())
        self.assertTrue(report["status"].startswith("too few points"), report["status"])
        np.testing.assert_array_equal(provenance, [0, 0, 0])
        np.testing.assert_array_equal(confidence, [1, 1, 1])

    def test_bad_arrays_raise_value_error(self):
        with self.assertRaisesRegex(ValueError, r"points: expected an N x 3 array, got shape \(4, 2\)"):
            graspfill.repair(np.zeros((4, 2), np.float32))
        with self.assertRaisesRegex(ValueError, r"got shape \(12,\)"):
            graspfill.repair(np.zeros(12))
        with self.assertRaisesRegex(ValueError, "points: expected float32 or float64, got int64"):
            graspfill.repair(np.zeros((4, 3), np.int64))
        bad = np.zeros((5, 3))
        bad[3, 1] = np.nan
        with self.assertRaisesRegex(ValueError, "points: row 3 is not finite"):
            graspfill.repair(bad)
        with self.assertRaisesRegex(ValueError, "points: row 0 is not finite"):
            graspfill.repair(np.full((1, 3), 1e300))  # beyond float32
        with self.assertRaisesRegex(ValueError, r"normals: expected one per point \(5\), got 4"):
            graspfill.repair(np.zeros((5, 3)), np.zeros((4, 3)))
        with self.assertRaisesRegex(ValueError, "up: expected a finite, non-zero direction"):
            graspfill.repair(np.zeros((5, 3)), up=(0, 0, 0))
        with self.assertRaisesRegex(ValueError, r"up: expected three numbers"):
            graspfill.repair(np.zeros((5, 3)), up="up")
        with self.assertRaisesRegex(ValueError, r"points: expected an N x 3 array, got shape \(\)"):
            graspfill.repair(None)

    def test_strided_views_are_read_as_they_are_seen(self):
        wide = np.arange(30, dtype=np.float32).reshape(5, 6) * 1e-3
        view = wide[:, ::2]  # not contiguous
        points, _, _, _ = graspfill.repair(view)
        np.testing.assert_array_equal(points, view)


class PlyTest(ScratchDirTest):
    def test_round_trip(self):
        rng = np.random.default_rng(7)
        points = rng.uniform(-0.05, 0.05, (1000, 3)).astype(np.float32)
        normals = points / np.linalg.norm(points, axis=1, keepdims=True)
        provenance = rng.integers(0, 3, 1000).astype(np.uint8)
        confidence = rng.uniform(0, 1, 1000).astype(np.float32)
        path = os.path.join(self.dir, "round.ply")
        graspfill.write_ply(path, points, provenance=provenance, confidence=confidence, normals=normals)
        cloud = graspfill.read_ply(path)
        self.assertEqual(cloud["points"].tobytes(), points.tobytes())
        self.assertEqual(cloud["normals"].tobytes(), normals.astype(np.float32).tobytes())
        np.testing.assert_array_equal(cloud["provenance"], provenance)
        np.testing.assert_array_equal(cloud["confidence"], confidence)
        self.assertEqual(cloud["T_C_G"].shape, (4, 4))

    def test_points_alone_read_back_observed(self):
        path = os.path.join(self.dir, "plain.ply")
        graspfill.write_ply(path, np.eye(3))
        cloud = graspfill.read_ply(path)
        np.testing.assert_array_equal(cloud["points"], np.eye(3, dtype=np.float32))
        self.assertIsNone(cloud["normals"])
        np.testing.assert_array_equal(cloud["provenance"], [0, 0, 0])
        np.testing.assert_array_equal(cloud["confidence"], [1, 1, 1])

    def test_the_file_is_the_clis(self):
        # A cloud written from Python is the CLI's input: `repair` reads it.
        path = os.path.join(self.dir, "tiny.ply")
        graspfill.write_ply(path, np.zeros((3, 3)))
        out = run_cli("repair", path, "-o", os.path.join(self.dir, "tiny_out.ply"))
        self.assertIn("3 points in, 3 out", out)

    def test_pcd_by_its_name(self):
        path = os.path.join(self.dir, "cloud.pcd")
        graspfill.write_ply(path, np.eye(3))
        with open(path, "rb") as f:
            self.assertTrue(f.read(64).startswith(b"# .PCD"))

    def test_refusals(self):
        with self.assertRaisesRegex(RuntimeError, "missing.ply"):
            graspfill.read_ply(os.path.join(self.dir, "missing.ply"))
        with self.assertRaisesRegex(ValueError, r"\.xyz"):
            graspfill.write_ply(os.path.join(self.dir, "cloud.xyz"), np.eye(3))
        with self.assertRaisesRegex(ValueError, "provenance: value 3 at 1"):
            graspfill.write_ply(os.path.join(self.dir, "p.ply"), np.eye(3), provenance=[0, 3, 0])
        with self.assertRaisesRegex(ValueError, r"confidence: expected shape \(3,\)"):
            graspfill.write_ply(os.path.join(self.dir, "c.ply"), np.eye(3), confidence=np.ones(2))
        with self.assertRaisesRegex(ValueError, "confidence: value"):
            graspfill.write_ply(os.path.join(self.dir, "c.ply"), np.eye(3), confidence=[0.5, 2.0, 0.5])


class BusTest(ScratchDirTest):
    """The bundled recording's repaired cloud, as published by `replay`."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.ply = os.path.join(cls.dir, "cloud.ply")
        cls.log = os.path.join(cls.dir, "bus.lcmlog")
        run_cli("replay", os.path.join(SOURCE_DIR, "replay", "default", "recording.lcmlog"), "-o", cls.ply,
                "--lcm-url", f"file://{cls.log}?mode=w")
        cls.messages = [data for _, channel, data in read_events(cls.log) if channel == CHANNEL]

    def assert_is_the_ply(self, cloud):
        ply = graspfill.read_ply(self.ply)
        self.assertEqual(cloud["points"].shape, ply["points"].shape)
        # The wire format may quantize positions (issue 38: a compact
        # encoding); 0.1 mm bounds any step it may take.
        np.testing.assert_allclose(cloud["points"], ply["points"], rtol=0, atol=1e-4)
        np.testing.assert_array_equal(cloud["provenance"], ply["provenance"])
        self.assertGreater(np.count_nonzero(cloud["provenance"]), 0)  # repaired: points added
        self.assertGreater(len(cloud["holes"]), 0)
        self.assertTrue(cloud["is_final"])

    def test_decode_object_cloud(self):
        self.assertEqual(len(self.messages), 1)
        cloud = graspfill.decode_object_cloud(self.messages[0])
        self.assert_is_the_ply(cloud)
        self.assertEqual(cloud["frame_name"], "gripper")
        self.assertEqual(cloud["T_C_G"].shape, (4, 4))
        np.testing.assert_allclose(cloud["T_C_G"][3], [0, 0, 0, 1])
        for hole in cloud["holes"]:
            self.assertIn(hole["kind"], ("claw", "missing_surface"))
            self.assertTrue(all(lo <= hi for lo, hi in zip(hole["box_min"], hole["box_max"])))
        # bytearray and memoryview are bytes too.
        again = graspfill.decode_object_cloud(memoryview(bytearray(self.messages[0])))
        self.assertEqual(again["points"].tobytes(), cloud["points"].tobytes())

    def test_bad_bytes_raise_value_error(self):
        with self.assertRaisesRegex(ValueError, r"object_cloud_t: .*\(malformed\)"):
            graspfill.decode_object_cloud(self.messages[0][:-7])
        with self.assertRaisesRegex(ValueError, "object_cloud_t"):
            graspfill.decode_object_cloud(b"")

    def test_subscriber_receives_the_published_cloud(self):
        # LCM's file:// provider plays the log to the subscriber: the same
        # code path as a live bus, without a network.
        with graspfill.Subscriber(url=f"file://{self.log}?speed=0") as subscriber:
            self.assertEqual(subscriber.channel, CHANNEL)
            cloud = subscriber.next(timeout_s=10.0)
            self.assertIsNotNone(cloud)
            self.assert_is_the_ply(cloud)
            with self.assertRaisesRegex(EOFError, "LCM ended"):  # the log had one
                subscriber.next(timeout_s=10.0)
            self.assertEqual(subscriber.bad_messages, 0)
        with self.assertRaisesRegex(ValueError, "closed"):
            subscriber.next(timeout_s=0)

    def test_iterating_a_log_stops_at_its_end(self):
        with graspfill.Subscriber(url=f"file://{self.log}?speed=0") as subscriber:
            clouds = list(subscriber)
        self.assertEqual(len(clouds), 1)
        self.assert_is_the_ply(clouds[0])

    def test_subscriber_skips_and_counts_what_does_not_decode(self):
        # The recording's gripper states on the subscribed channel: none is
        # an object_cloud_t; each is counted, and the log's end is reached.
        recording = os.path.join(SOURCE_DIR, "replay", "default", "recording.lcmlog")
        channel = "GRASPFILL_GRIPPER_STATE"
        states = sum(1 for _, name, _ in read_events(recording) if name == channel)
        self.assertGreater(states, 0)
        with graspfill.Subscriber(channel=channel, url=f"file://{recording}?speed=0") as subscriber:
            self.assertEqual(list(subscriber), [])
            self.assertEqual(subscriber.bad_messages, states)
            self.assertIn("object_cloud_t", subscriber.last_error)

    def test_subscriber_refusals(self):
        with self.assertRaisesRegex(RuntimeError, "nosuch://"):
            graspfill.Subscriber(url="nosuch://")
        with self.assertRaisesRegex(ValueError, "channel is empty"):
            graspfill.Subscriber(channel="", url="memq://")
        with graspfill.Subscriber(url="memq://") as subscriber:
            with self.assertRaisesRegex(ValueError, "timeout_s"):
                subscriber.next(timeout_s=-1)
            self.assertIsNone(subscriber.next(timeout_s=0.05))


if __name__ == "__main__":
    unittest.main(verbosity=2)
