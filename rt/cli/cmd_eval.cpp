// SPDX-License-Identifier: BSD-3-Clause
// `graspfill eval PRED.ply GT.ply [--json]`: compares a predicted object
// cloud with its ground truth (chamfer distance of paper Eq. 6, F-scores,
// percentiles) and prints a summary or one JSON object.
//
// A .ply file is read by graspfill's own PLY reader (io/ply.hpp, which
// checks the header and every count before it allocates; Open3D's crashed
// on a 44-byte header); other formats Open3D knows (PCD, XYZ, ...) by
// Open3D's point-cloud reader. A mesh PLY given as ground truth is read as
// its vertices only; that is fine for densely sampled meshes, but a coarse
// mesh should be sampled into a cloud first.
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/utility/Logging.h>

#include <cctype>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "error_text.hpp"
#include "eval/metrics.hpp"
#include "graspfill/io/ply.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kEvalUsage =
    "usage: graspfill eval PRED GT [--json]\n"
    "  PRED    predicted (repaired) cloud, meters (PLY/PCD/XYZ...)\n"
    "  GT      hole-free ground-truth cloud, same frame; a mesh PLY is\n"
    "          read as its vertices only\n"
    "  --json  print one JSON object instead of the summary\n"
    "prints the chamfer distance (paper Eq. 6) in mm^2, F-scores at 1 and\n"
    "2 mm, coverage (share of GT within 2 mm of PRED) and precision at\n"
    "2 mm, 95th-percentile NN distances in mm and the point counts\n"
    "example: graspfill eval repaired.ply gt_cloud.ply --json\n";

// Lowers Open3D's log level for a scope (its own context manager needs
// explicit Enter/Exit, which an early return or exception would skip).
class QuietOpen3D {
 public:
  QuietOpen3D() : saved_(open3d::utility::GetVerbosityLevel()) {
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  }
  ~QuietOpen3D() { open3d::utility::SetVerbosityLevel(saved_); }
  QuietOpen3D(const QuietOpen3D&) = delete;
  QuietOpen3D& operator=(const QuietOpen3D&) = delete;

 private:
  open3d::utility::VerbosityLevel saved_;
};

// A PLY file by its extension (case-insensitive), as Open3D would pick its
// reader.
bool IsPly(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".ply";
}

// Reads `path` as a cloud of finite points; on failure prints why (naming
// the file) and returns nothing.
std::optional<std::vector<Eigen::Vector3f>> LoadCloud(const std::string& path, const char* role) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    const bool exists = std::filesystem::exists(path, ec);
    std::fprintf(stderr, "graspfill eval: %s file '%s' %s\n", role, path.c_str(),
                 exists ? "is not a regular file" : "does not exist");
    return std::nullopt;
  }
  open3d::geometry::PointCloud cloud;
  if (IsPly(path)) {
    try {
      for (const Eigen::Vector3f& p : io::ReadCloudPly(path).points_G)
        cloud.points_.push_back(p.cast<double>());
    } catch (const std::exception& e) {  // names the file and what is wrong
      std::fprintf(stderr, "graspfill eval: %s file: %s\n", role, ErrorText(e).c_str());
      return std::nullopt;
    }
  } else {
    bool ok = false;
    {
      // Our own message names the file; Open3D's warnings would only repeat it.
      QuietOpen3D quiet;
      ok = open3d::io::ReadPointCloud(path, cloud);
    }
    if (!ok) {
      std::fprintf(stderr, "graspfill eval: cannot read %s file '%s'\n", role, path.c_str());
      return std::nullopt;
    }
  }
  if (cloud.points_.empty()) {
    std::fprintf(stderr, "graspfill eval: %s file '%s' has no points\n", role, path.c_str());
    return std::nullopt;
  }
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.points_.size());
  for (size_t i = 0; i < cloud.points_.size(); ++i) {
    const Eigen::Vector3f p = cloud.points_[i].cast<float>();
    // Checked here (not only in Compare) so the message can name the file.
    if (!p.allFinite()) {
      std::fprintf(stderr,
                   "graspfill eval: %s file '%s' has a non-finite point at "
                   "index %zu\n",
                   role, path.c_str(), i);
      return std::nullopt;
    }
    points.push_back(p);
  }
  return points;
}

nlohmann::json ToJson(const eval::CloudMetrics& m, const std::string& pred, const std::string& gt) {
  return nlohmann::json{
      {"pred", pred},
      {"gt", gt},
      {"chamfer_mm2", m.chamfer_mm2},
      {"pred_to_gt_mean_sq_mm2", m.pred_to_gt_mean_sq_mm2},
      {"gt_to_pred_mean_sq_mm2", m.gt_to_pred_mean_sq_mm2},
      {"fscore_1mm", m.fscore_1mm},
      {"fscore_2mm", m.fscore_2mm},
      {"coverage_2mm", m.coverage_2mm},
      {"precision_2mm", m.precision_2mm},
      {"p95_pred_to_gt_mm", m.p95_pred_to_gt_mm},
      {"p95_gt_to_pred_mm", m.p95_gt_to_pred_mm},
      {"max_pred_to_gt_mm", m.max_pred_to_gt_mm},
      {"num_pred", m.num_pred},
      {"num_gt", m.num_gt},
  };
}

}  // namespace

int RunEval(const Args& args) {
  bool json = false;
  std::vector<std::string> files;
  for (const std::string& arg : args) {
    if (arg == "--help" || arg == "-h") {
      std::fputs(kEvalUsage, stdout);
      return 0;
    }
    if (arg == "--json") {
      json = true;
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr, "graspfill eval: %s\n", BadOptionText(arg, kEvalUsage).c_str());
      std::fputs(kEvalUsage, stderr);
      return 2;
    } else {
      files.push_back(arg);
    }
  }
  if (files.size() != 2) {
    std::fprintf(stderr, "graspfill eval: expected 2 files, got %zu\n", files.size());
    std::fputs(kEvalUsage, stderr);
    return 2;
  }
  const std::string& pred_path = files[0];
  const std::string& gt_path = files[1];

  const auto pred = LoadCloud(pred_path, "predicted");
  if (!pred) return 1;
  const auto gt = LoadCloud(gt_path, "ground-truth");
  if (!gt) return 1;

  const eval::CloudMetrics m = eval::Compare(*pred, *gt);
  if (json) {
    std::printf("%s\n", ToJson(m, pred_path, gt_path).dump(2).c_str());
    return 0;
  }
  std::printf(
      "pred: %s (%zu points)\n"
      "gt:   %s (%zu points)\n"
      "chamfer (Eq. 6): %.6g mm^2 (pred->gt %.6g + gt->pred %.6g)\n"
      "F-score: %.4f @1mm, %.4f @2mm; at 2 mm: coverage %.4f, precision %.4f\n"
      "p95 distance: pred->gt %.4g mm, gt->pred %.4g mm; max pred->gt %.4g "
      "mm\n",
      pred_path.c_str(), m.num_pred, gt_path.c_str(), m.num_gt, m.chamfer_mm2, m.pred_to_gt_mean_sq_mm2,
      m.gt_to_pred_mean_sq_mm2, m.fscore_1mm, m.fscore_2mm, m.coverage_2mm, m.precision_2mm,
      m.p95_pred_to_gt_mm, m.p95_gt_to_pred_mm, m.max_pred_to_gt_mm);
  return 0;
}

}  // namespace graspfill::cli
