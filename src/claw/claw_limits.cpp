// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/claw_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw {
namespace {

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", v);
  return text;
}

std::string Beyond(double value, const char* unit, double limit, const char* limit_note = "") {
  return Number(value) + " " + unit + " is beyond the " + Number(limit) + " " + unit + limit_note + " limit";
}

}  // namespace

std::string DistanceDefect(double value_m) {
  if (!std::isfinite(value_m)) return "is not a finite number";
  if (std::abs(value_m) > kMaxClawReachM) return Beyond(value_m, "m", kMaxClawReachM);
  return "";
}

std::string SizeDefect(double value_m) {
  if (const std::string defect = DistanceDefect(value_m); !defect.empty()) return defect;
  if (!(value_m > 0.0)) return Number(value_m) + " m: must be more than 0";
  return "";
}

std::string AngleDefect(double value_rad) {
  if (!std::isfinite(value_rad)) return "is not a finite number";
  if (std::abs(value_rad) > kMaxClawAngleRad) {
    return Beyond(value_rad, "rad", kMaxClawAngleRad, " (4 pi)");
  }
  return "";
}

std::string ScaleDefect(double scale) {
  if (!std::isfinite(scale)) return "scale is not a finite number";
  if (!(scale > 0.0)) return "scale " + Number(scale) + ": must be more than 0";
  if (scale > kMaxMeshScale) {
    return "scale " + Number(scale) + " is beyond the limit of " + Number(kMaxMeshScale);
  }
  return "";
}

std::string MeshExtentDefect(const TriangleMesh& mesh) {
  std::vector<bool> checked(mesh.vertices.size(), false);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int index = t[k];
      if (index < 0 || index >= static_cast<int>(mesh.vertices.size()) || checked[index]) continue;
      checked[index] = true;
      const double far = mesh.vertices[index].cast<double>().norm();
      if (!(far <= kMaxClawReachM)) {
        // A file in millimetres read as meters is the usual cause.
        const bool mm = far >= 10.0 * kMaxClawReachM && far <= 1000.0 * kMaxClawReachM;
        return "vertex " + std::to_string(index) + " lies " + Number(far) +
               " m from the mesh's origin, beyond the " + Number(kMaxClawReachM) + " m limit" +
               (mm ? " (a mesh in mm needs a scale of 0.001)" : "");
      }
    }
  }
  return "";
}

std::string LinkCountDefect(int64_t count) {
  if (count <= kMaxClawLinks) return "";
  return std::to_string(count) + " links, over the limit of " + std::to_string(kMaxClawLinks) + " per claw";
}

double ClawReachBoundM(const ClawModel& model, std::string* farthest_link) {
  const std::vector<Link>& links = model.links();
  // Per link: how far its frame's origin can be from G's (parents first).
  std::vector<double> origin_reach(links.size(), 0.0);
  double bound = 0.0;
  for (size_t i = 0; i < links.size(); ++i) {
    const Joint& joint = links[i].joint;
    double reach = joint.T_parent_joint.translation().norm();
    if (joint.type == JointType::kPrismatic) {
      reach += std::max(std::abs(joint.lower), std::abs(joint.upper));
    }
    origin_reach[i] = reach + (links[i].parent >= 0 ? origin_reach[links[i].parent] : 0.0);
    if (links[i].mesh.empty()) continue;
    double farthest = 0.0;
    for (const Eigen::Vector3i& t : links[i].mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        farthest = std::max(farthest, links[i].mesh.vertices[t[k]].cast<double>().norm());
      }
    }
    const double total = origin_reach[i] + links[i].T_link_mesh.translation().norm() + farthest;
    if (!(total <= bound)) {  // NaN too
      bound = total;
      if (farthest_link != nullptr) *farthest_link = links[i].name;
    }
  }
  return bound;
}

std::string ClawReachDefect(const ClawModel& model) {
  std::string link;
  const double bound = ClawReachBoundM(model, &link);
  if (bound <= kMaxClawReachM) return "";
  return "the claw reaches up to " + Number(bound) + " m from G's origin (link '" + link +
         "': its chain's origins and travels, its mesh's origin and farthest vertex added up), "
         "beyond the " +
         Number(kMaxClawReachM) + " m limit";
}

}  // namespace graspfill::claw
