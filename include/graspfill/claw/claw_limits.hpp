// SPDX-License-Identifier: BSD-3-Clause
// The sizes a claw may have, stated once (issue 36). Every claw file is held
// to them: description files (claw_loader.cpp), URDFs and URDF configs
// (urdf_claw.cpp), and so the claws that session descriptions carry. A real
// claw is about 0.3 m across, with 3 to 30 links and 10^3 to 10^4
// triangles (the Robotiq 3-Finger's collision meshes: 13 links, 5,505
// triangles, a reach bound of 0.296 m; the Franka hand: 3 links, 304
// triangles, 0.221 m); the limits leave real ones inside them and refuse,
// with a message in words, what would otherwise run for minutes, take
// gigabytes or end in an allocator's error.
#pragma once

#include <cstdint>
#include <string>

#include "graspfill/types.hpp"

namespace graspfill::claw {

class ClawModel;

/// Distances [m]: no point of the claw may lie farther from G's origin, in
/// any pose its joints allow. Each distance read is held to it where it is
/// read (every origin's xyz, a prismatic joint's limits, a box's edges, a
/// cylinder's radius and length, a sphere's radius, a vertex's distance
/// from its mesh's origin), and the whole claw once loaded (ClawReachDefect).
/// Why 0.5 m: the pose refinement keeps a dense closest-point table over
/// the claw's box at 1.5 mm, whose size goes with the claw's volume: a
/// 1 m cube as the claw made `replay` of 10 frames take 2.7 GB and 72 s,
/// the largest cube within the limit (0.57 m) 0.58 GB and 7.6 s, the
/// Robotiq 3-Finger 0.12 GB and 1.6 s.
constexpr double kMaxClawReachM = 0.5;
/// Angles [rad]: every rpy and a revolute joint's limits (two turns either
/// way: more is a broken file, e.g. degrees where radians belong).
constexpr double kMaxClawAngleRad = 12.566370614359172;  // 4 pi
/// A mesh's scale factor, each axis, in (0, 1000] (0.001: a file in mm).
constexpr double kMaxMeshScale = 1000.0;
/// Links per claw: a description's links or a URDF's <link>s.
constexpr int kMaxClawLinks = 256;
/// Triangles per claw, every link's mesh together (the claw mask and the
/// pose refinement use them for every depth frame). Over it is an error,
/// not a decimation: a claw model is made once, offline, and which
/// simplification fits is the user's to choose (e.g. the URDF's collision
/// meshes rather than its visual ones).
constexpr int64_t kMaxClawTriangles = 1000000;
/// Bytes of one mesh file, refused before it is read (1,000,000 triangles
/// of binary STL are 50 MB, of ASCII STL some 250 MB: over the limit, as
/// is any file that could not fit under the triangle limit).
constexpr int64_t kMaxMeshFileBytes = int64_t{128} << 20;
/// Bytes of a claw description, URDF or URDF config.
constexpr int64_t kMaxClawFileBytes = int64_t{16} << 20;

/// "" when `value_m` is within kMaxClawReachM either way, else in words:
/// "1e+30 m is beyond the 0.5 m limit", "is not a finite number".
std::string DistanceDefect(double value_m);
/// As DistanceDefect, and more than 0: a box edge, a radius, a length.
std::string SizeDefect(double value_m);
/// "" when `value_rad` is within kMaxClawAngleRad either way, else e.g.
/// "1e+300 rad is beyond the 12.5664 rad (4 pi) limit".
std::string AngleDefect(double value_rad);
/// "" for a scale in (0, kMaxMeshScale], else why not.
std::string ScaleDefect(double scale);
/// "" when every vertex a triangle uses lies within kMaxClawReachM of the
/// mesh's origin, else the first that does not, e.g. "vertex 3 lies 120 m
/// from the mesh's origin, beyond the 0.5 m limit (a mesh in mm needs a
/// scale of 0.001)".
std::string MeshExtentDefect(const TriangleMesh& mesh);
/// "" when `count` links are within kMaxClawLinks, else "10000 links, over
/// the limit of 256 per claw".
std::string LinkCountDefect(int64_t count);
/// How far from G's origin a point of `model` can lie, at most, in any
/// pose: each link's chain of joint origins, prismatic travels and mesh
/// origin, and its mesh's farthest vertex, added up (rotations move nothing
/// farther from a joint's origin), whatever the opening or joint values.
/// `farthest_link`, if given, gets the link that reaches farthest.
double ClawReachBoundM(const ClawModel& model, std::string* farthest_link = nullptr);
/// "" when ClawReachBoundM is within kMaxClawReachM, else e.g. "the claw reaches up to 0.87 m from G's origin
/// (link 'finger_3': its chain's origins and travels and its mesh added up), beyond the 0.5 m limit".
std::string ClawReachDefect(const ClawModel& model);

}  // namespace graspfill::claw
