// SPDX-License-Identifier: BSD-3-Clause
// graspfill claw SPEC --opening X -o claw.ply: the claw posed at an opening
// (and joint values), written in the gripper frame G to inspect a
// description or URDF claw before a recording is made with it.
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "claw_option.hpp"
#include "commands.hpp"
#include "data_paths.hpp"
#include "error_text.hpp"
#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/io/ply.hpp"
#include "number_parsing.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kClawUsage =
    "usage: graspfill claw SPEC [--opening X] [--joints Q1,Q2,...] [--claw-mesh-root DIR]\n"
    "                      -o CLAW.ply [--force]\n"
    "  SPEC              three-finger, parallel, a description (.json), a URDF (.urdf)\n"
    "                    or a URDF claw config (.json naming a URDF), or an installed\n"
    "                    description's name (robotiq_3f, franka_hand, robotiq_3f_urdf)\n"
    "  --opening X       the claw's opening in its own units (default 0; see the\n"
    "                    opening line printed: meters for the built-ins, 0 open .. 1\n"
    "                    closed for URDF claws)\n"
    "  --joints Q,...    joint values overriding the opening (the claw's joint_values order)\n"
    "  --claw-mesh-root DIR  where the claw's meshes (and a config's URDF) are\n"
    "writes the posed claw's surface in G (meters; +z the approach) and prints\n"
    "its links, triangles and bounds\n"
    "example: graspfill claw parallel --opening 0.06 -o parallel.ply\n";

std::vector<double> ParseJoints(const std::string& text) {
  std::vector<double> values;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    values.push_back(ParseDouble("--joints", item, -1e3, 1e3, ""));
  }
  if (values.empty()) throw UsageError("--joints '" + text + "': expected Q1,Q2,...");
  return values;
}

}  // namespace

int RunClaw(const Args& args) {
  std::string spec, out, mesh_root;
  double opening = 0.0;
  std::vector<double> joints;
  bool force = false;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      const bool has_value = i + 1 < args.size();
      if (a == "--help" || a == "-h") {
        std::fputs(kClawUsage, stdout);
        return 0;
      } else if ((a == "-o" || a == "--output") && has_value) {
        out = args[++i];
      } else if (a == "--force") {
        force = true;
      } else if (a == "--opening" && has_value) {
        opening = ParseDouble("--opening", args[++i], -1e3, 1e3, "");
      } else if (a == "--joints" && has_value) {
        joints = ParseJoints(args[++i]);
      } else if (a == "--claw-mesh-root" && has_value) {
        mesh_root = args[++i];
      } else if (!a.empty() && a[0] != '-' && spec.empty()) {
        spec = a;
      } else {
        throw BadOption(a, kClawUsage);
      }
    }
    if (spec.empty() || out.empty()) throw UsageError("need SPEC and -o CLAW.ply");
    spec = ResolveClawSpec(spec, InstalledClawsDir());
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill claw: %s\n%s", e.what(), kClawUsage);
    return 2;
  }
  try {
    io::CheckOutputFile(out, force);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill claw: %s\n", ErrorText(e).c_str());
    return 1;
  }
  const claw::ClawModel model = MakeClaw(spec, mesh_root);  // throws naming the file
  const TriangleMesh posed = model.Posed(opening, joints);
  io::WriteMeshPly(out, posed, io::ReplaceIf(force));
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : posed.vertices) box.extend(v);
  std::printf("%s: claw '%s', %zu links, %zu triangles\n", spec.c_str(), model.name().c_str(),
              model.links().size(), posed.triangles.size());
  for (const claw::Link& link : model.links()) {
    std::printf("  %-24s %7zu triangles", link.name.c_str(), link.mesh.triangles.size());
    if (link.degenerate_triangles_dropped > 0) {
      std::printf(" (%d zero-area triangles dropped)", link.degenerate_triangles_dropped);
    }
    std::printf("\n");
  }
  if (!model.opening_doc().empty()) std::printf("  opening: %s\n", model.opening_doc().c_str());
  std::printf("  reach: at most %.3f m from G's origin in any pose (limit %g m)\n",
              claw::ClawReachBoundM(model), claw::kMaxClawReachM);
  if (!posed.empty()) {
    std::printf("  bounds in G [m]: x %.4f..%.4f  y %.4f..%.4f  z %.4f..%.4f\n", box.min().x(), box.max().x(),
                box.min().y(), box.max().y(), box.min().z(), box.max().z());
  }
  std::printf("  -> %s\n", out.c_str());
  return 0;
}

}  // namespace graspfill::cli
