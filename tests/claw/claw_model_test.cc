// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/claw_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

namespace graspfill::claw {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Vertices are floats: positions agree to float precision at claw scale.
constexpr double kFloatTolM = 1e-6;

// Signed volume of a closed mesh (divergence theorem): > 0 when every
// triangle faces outwards.
double SignedVolume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

// Every directed edge must appear once and its reverse once: closed and
// consistently wound.
bool IsClosedAndConsistent(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    if (count != 1) return false;
    auto it = edges.find({edge.second, edge.first});
    if (it == edges.end() || it->second != 1) return false;
  }
  return true;
}

// Posed mesh of one link only (in G).
TriangleMesh PosedLink(const ClawModel& model, size_t link, double opening_m) {
  const auto poses = model.LinkPoses(opening_m);
  return model.links()[link].mesh.Transformed(poses[link] * model.links()[link].T_link_mesh);
}

TEST(ClawModelTest, LinkCounts) {
  EXPECT_EQ(ClawModel::ThreeFinger().links().size(), 4u);
  EXPECT_EQ(ClawModel::Parallel().links().size(), 3u);
  EXPECT_EQ(ClawModel::ThreeFinger().name(), "three_finger");
  EXPECT_EQ(ClawModel::Parallel().name(), "parallel");
}

TEST(ClawModelTest, LinksAreClosedAndOutwardFacing) {
  for (const ClawModel& model : {ClawModel::ThreeFinger(), ClawModel::Parallel()}) {
    for (const Link& link : model.links()) {
      EXPECT_TRUE(IsClosedAndConsistent(link.mesh)) << link.name;
      EXPECT_GT(SignedVolume(link.mesh), 0.0) << link.name;
    }
    const TriangleMesh posed = model.Posed(0.03);
    EXPECT_GT(SignedVolume(posed), 0.0);
  }
}

TEST(ClawModelTest, FingerVolumeMatchesConfig) {
  ProceduralClawConfig config;
  const ClawModel model = ClawModel::ThreeFinger(config);
  const double expected = config.finger_length_m * config.finger_width_m * config.finger_thickness_m;
  EXPECT_NEAR(SignedVolume(model.links()[1].mesh), expected, 1e-9);
}

TEST(ClawModelTest, InnerFaceAtOpeningRadius) {
  ProceduralClawConfig config;
  for (const ClawModel& model : {ClawModel::ThreeFinger(config), ClawModel::Parallel(config)}) {
    const int num_fingers = static_cast<int>(model.links().size()) - 1;
    for (double opening_m : {0.01, 0.035, 0.07}) {
      for (int f = 0; f < num_fingers; ++f) {
        const TriangleMesh finger_G = PosedLink(model, f + 1, opening_m);
        const double angle = 2.0 * kPi * f / num_fingers;
        const Eigen::Vector3d radial(std::cos(angle), std::sin(angle), 0.0);
        double min_r = std::numeric_limits<double>::infinity();
        double max_r = -min_r;
        double min_z = min_r;
        double max_z = -min_r;
        for (const Eigen::Vector3f& v : finger_G.vertices) {
          const double r = radial.dot(v.cast<double>());
          min_r = std::min(min_r, r);
          max_r = std::max(max_r, r);
          min_z = std::min(min_z, static_cast<double>(v.z()));
          max_z = std::max(max_z, static_cast<double>(v.z()));
        }
        EXPECT_NEAR(min_r, opening_m, kFloatTolM) << model.name() << f;
        EXPECT_NEAR(max_r, opening_m + config.finger_thickness_m, kFloatTolM);
        EXPECT_NEAR(min_z, 0.0, kFloatTolM);
        EXPECT_NEAR(max_z, config.finger_length_m, kFloatTolM);
      }
    }
  }
}

TEST(ClawModelTest, FingerZeroAlongPlusX) {
  const ClawModel model = ClawModel::ThreeFinger();
  const TriangleMesh finger_G = PosedLink(model, 1, 0.04);
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& v : finger_G.vertices) centroid += v;
  centroid /= static_cast<float>(finger_G.vertices.size());
  EXPECT_GT(centroid.x(), 0.04f);
  EXPECT_NEAR(centroid.y(), 0.0f, kFloatTolM);
}

TEST(ClawModelTest, OpeningClampsToLimits) {
  ProceduralClawConfig config;
  const ClawModel model = ClawModel::ThreeFinger(config);
  const auto low = model.LinkPoses(-1.0);
  const auto high = model.LinkPoses(10.0);
  EXPECT_NEAR(low[1].translation().x(), config.min_opening_m, 1e-12);
  EXPECT_NEAR(high[1].translation().x(), config.max_opening_m, 1e-12);
  EXPECT_NEAR(high[1].translation().norm(), config.max_opening_m, 1e-12);
  EXPECT_NEAR(high[2].translation().norm(), config.max_opening_m, 1e-12);
}

TEST(ClawModelTest, PalmSpansThickness) {
  ProceduralClawConfig config;
  const TriangleMesh palm = PosedLink(ClawModel::ThreeFinger(config), 0, 0.03);
  float min_z = 1, max_z = -1, max_r = 0;
  for (const Eigen::Vector3f& v : palm.vertices) {
    min_z = std::min(min_z, v.z());
    max_z = std::max(max_z, v.z());
    max_r = std::max(max_r, v.head<2>().norm());
  }
  EXPECT_NEAR(min_z, -config.palm_thickness_m, kFloatTolM);
  EXPECT_NEAR(max_z, 0.0, kFloatTolM);
  EXPECT_NEAR(max_r, config.palm_radius_m, kFloatTolM);
}

TEST(ClawModelTest, PosedMergesAllLinks) {
  const ClawModel model = ClawModel::ThreeFinger();
  size_t triangles = 0;
  for (const Link& link : model.links()) triangles += link.mesh.triangles.size();
  EXPECT_EQ(model.Posed(0.03).triangles.size(), triangles);
}

TEST(ClawModelTest, JointValuesOverrideOpening) {
  std::vector<Link> links(2);
  links[0].name = "base";
  links[1].name = "slider";
  links[1].parent = 0;
  links[1].joint.type = JointType::kPrismatic;
  links[1].joint.axis = Eigen::Vector3d(0, 2, 0);  // normalized by the model
  links[1].joint.lower = -1.0;
  links[1].joint.upper = 1.0;
  links[1].joint.joint_index = 1;
  const ClawModel model("test", links);
  EXPECT_NEAR(model.LinkPoses(0.5)[1].translation().y(), 0.5, 1e-12);
  EXPECT_NEAR(model.LinkPoses(0.5, {0.0, -0.25})[1].translation().y(), -0.25, 1e-12);
  EXPECT_NEAR(model.LinkPoses(0.5, {0.0, 7.0})[1].translation().y(), 1.0, 1e-12);
}

TEST(ClawModelTest, RejectsParentAfterChild) {
  std::vector<Link> links(2);
  links[0].parent = 1;
  EXPECT_THROW(ClawModel("bad", links), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::claw
