// The chained repair: contract tests (input kept, provenance, bad input,
// no-op cases). Accuracy against the paper's tables is `graspfill bench
// repair`'s job.
#include "graspfill/repair/repairer.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "graspfill/synth/mesh_sampling.hpp"
#include "graspfill/synth/paper_protocol.hpp"
#include "graspfill/synth/shapes.hpp"

namespace graspfill::repair {
namespace {

ObjectCloud Cloud(const std::vector<Eigen::Vector3f>& points) {
  ObjectCloud c;
  c.points_G = points;
  return c;
}

TEST(Repairer, KeepsEveryInputPointAndLabelsTheAddedOnes) {
  synth::PaperProtocolConfig pc;
  pc.shape = synth::Shape::kCylinder;
  pc.num_points = 20000;
  const synth::PaperProtocolCloud c = synth::MakePaperProtocolCloud(pc);
  const RepairResult r = Repair(Cloud(c.holey));
  ASSERT_GE(r.cloud.size(), c.holey.size());
  ASSERT_EQ(r.cloud.provenance.size(), r.cloud.size());
  for (size_t i = 0; i < c.holey.size(); ++i) {
    ASSERT_EQ(r.cloud.points_G[i], c.holey[i]) << i;
    ASSERT_EQ(r.cloud.provenance[i], Provenance::kObserved);
  }
  int surface = 0, symmetry = 0;
  for (size_t i = c.holey.size(); i < r.cloud.size(); ++i) {
    ASSERT_NE(r.cloud.provenance[i], Provenance::kObserved);
    surface += r.cloud.provenance[i] == Provenance::kSurface;
    symmetry += r.cloud.provenance[i] == Provenance::kSymmetry;
  }
  int reported = 0;
  for (const HoleSummary& h : r.report.holes) reported += h.points_added;
  EXPECT_EQ(reported, surface + symmetry);
  EXPECT_FALSE(r.report.timings.empty());
}

// A closed surface has no holes: random-sample density gaps and sharp
// edges must not be taken for hole boundaries.
TEST(Repairer, ClosedSurfaceComesBackUnchanged) {
  for (const synth::Shape shape : {synth::Shape::kSphere, synth::Shape::kCuboid, synth::Shape::kCylinder}) {
    for (const int points : {20000, 50000}) {
      const TriangleMesh mesh = synth::MakeShape(shape, synth::DefaultSize(shape));
      const synth::SurfaceSamples s = synth::SampleSurface(mesh, points, 3);
      const RepairResult r = Repair(Cloud(s.points));
      SCOPED_TRACE(synth::ShapeName(shape) + ", " + std::to_string(points) + " points");
      EXPECT_EQ(r.cloud.size(), s.points.size());
      EXPECT_EQ(r.report.status, "no holes found");
    }
  }
}

TEST(Repairer, TinyCloudIsANoOpWithAReason) {
  const RepairResult r = Repair(Cloud({{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, 0}}));
  EXPECT_EQ(r.cloud.size(), 3u);
  EXPECT_NE(r.report.status.find("too few points"), std::string::npos);
}

TEST(Repairer, NonFiniteInputThrowsNamingThePoint) {
  std::vector<Eigen::Vector3f> points(500, Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  points[17].y() = std::nanf("");
  try {
    Repair(Cloud(points));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 17"), std::string::npos) << e.what();
  }
}

TEST(RepairConfig, DefaultsValidateAndBadHintIsRejected) {
  EXPECT_NO_THROW(RepairConfig{}.Validate());
  RepairConfig c;
  c.up_hint = Eigen::Vector3d::Zero();
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::repair
