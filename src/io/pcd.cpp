// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/pcd.hpp"

#include <Eigen/Geometry>

#include "cloud_encoding.hpp"
#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/io/messages.hpp"

namespace graspfill::io {
namespace {

// The provenance's colour as PCL packs an `rgb` field: 0x00RRGGBB in the
// four bytes of a float, little-endian.
void AppendPackedRgb(std::string* out, Provenance p) {
  const Rgb8 c = ProvenanceColor(p);
  out->push_back(static_cast<char>(c[2]));
  out->push_back(static_cast<char>(c[1]));
  out->push_back(static_cast<char>(c[0]));
  out->push_back(0);
}

// "tx ty tz qw qx qy qz"; + 0.0 turns a -0 (an inverted identity's) into 0.
std::string Pose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  std::string text;
  for (const double v : {t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()}) {
    text += (text.empty() ? "" : " ") + FormatDouble(v + 0.0);
  }
  return text;
}

}  // namespace

void WriteCloudPcd(const std::string& path, const ObjectCloud& cloud, IfExists if_exists) {
  const std::string what = "cannot write PCD";
  CheckOnePerPoint(cloud, what, path);
  const size_t n = cloud.points_G.size();
  const bool has_normals = !cloud.normals_G.empty();
  const bool has_confidence = !cloud.confidence.empty();
  const Eigen::Quaterniond q_C_G = Eigen::Quaterniond(cloud.T_C_G.rotation()).normalized();
  const Eigen::Isometry3d T_G_C = cloud.T_C_G.inverse();
  const Eigen::Quaterniond q_G_C = Eigen::Quaterniond(T_G_C.rotation()).normalized();

  std::string fields = "x y z", sizes = "4 4 4", types = "F F F", counts = "1 1 1";
  const auto add = [&](const char* name, const char* size, const char* type) {
    fields += std::string(" ") + name;
    sizes += std::string(" ") + size;
    types += std::string(" ") + type;
    counts += " 1";
  };
  if (has_normals) {
    for (const char* name : {"normal_x", "normal_y", "normal_z"}) add(name, "4", "F");
  }
  add("rgb", "4", "F");
  add("provenance", "1", "U");
  if (has_confidence) add("confidence", "4", "F");

  std::string bytes;
  bytes.reserve(768 + n * (21 + (has_normals ? 12 : 0) + (has_confidence ? 4 : 0)));
  bytes += "# .PCD v0.7 - Point Cloud Data file format\n";
  bytes += "# graspfill object cloud, gripper frame G, meters\n";
  // The version only (no date): the same cloud must give the same bytes.
  bytes += "# graspfill software " + SoftwareVersion() + "\n";
  bytes += "# graspfill frame_name " + OneLine(cloud.frame_name) + "\n";
  bytes += "# graspfill utime " + std::to_string(cloud.utime) + "\n";
  bytes += "# graspfill seq " + std::to_string(cloud.seq) + "\n";
  bytes += "# graspfill T_C_G " + Pose(cloud.T_C_G.translation(), q_C_G) + "\n";
  bytes += "# provenance: 0 observed, 1 surface repair, 2 symmetry; rgb: its colour\n";
  bytes += "VERSION 0.7\n";
  bytes += "FIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\n";
  bytes += "WIDTH " + std::to_string(n) + "\nHEIGHT 1\n";
  bytes += "VIEWPOINT " + Pose(T_G_C.translation(), q_G_C) + "\n";
  bytes += "POINTS " + std::to_string(n) + "\nDATA binary\n";
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.points_G[i][k]);
    if (has_normals) {
      for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.normals_G[i][k]);
    }
    const Provenance p = cloud.provenance.empty() ? Provenance::kObserved : cloud.provenance[i];
    AppendPackedRgb(&bytes, p);
    bytes.push_back(static_cast<char>(p));
    if (has_confidence) AppendFloat(&bytes, cloud.confidence[i]);
  }
  WriteFileAtomically(path, bytes, what, if_exists);
}

}  // namespace graspfill::io
