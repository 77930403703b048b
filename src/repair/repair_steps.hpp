// SPDX-License-Identifier: BSD-3-Clause
// The steps' own settings, internal to the repair library: each step's
// config struct, at the defaults its header documents. No caller of the
// library sets them (RepairConfig in repairer.hpp is the public knob set);
// the tests that pin one step's effect on the whole chain do, through
// RepairWithSteps.
#pragma once

#include "analysis_cloud.hpp"
#include "axis_refinement.hpp"
#include "boundary_classification.hpp"
#include "boundary_completion.hpp"
#include "boundary_detection.hpp"
#include "boundary_linking.hpp"
#include "claw_hole_repair.hpp"
#include "evidence_config.hpp"
#include "graspfill/repair/repairer.hpp"
#include "outlier_removal.hpp"
#include "symmetry_repair.hpp"
#include "virtual_frame.hpp"

namespace graspfill::repair {

struct RepairSteps {
  AnalysisConfig analysis;  ///< best mode only: the paper works on the input
  OutlierConfig outliers;
  BoundaryConfig boundary;
  LinkConfig link;
  VirtualFrameConfig frame;
  AxisRefineConfig axis;  ///< best mode only (the paper has no such step)
  ClassifyConfig classify;
  CompletionConfig completion;
  ClawRepairConfig claw;
  SymmetryConfig symmetry;
  /// With a visibility record (best mode): the mirror test, the free-space
  /// filter and the top's height.
  EvidenceConfig evidence;

  /// graspfill's defaults (kBest), or the paper's published parameters
  /// (kPaper: Poisson depth 6 over the side points, the plain cross-section
  /// search, no axis refinement, no boundary-axis check, the input as it is).
  static RepairSteps For(RepairMode mode);
  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// What every step sees: the public settings and the steps' own.
struct RepairSettings : RepairConfig, RepairSteps {};

/// Repair() with the steps' settings given instead of For(config.mode)'s.
/// In paper mode the rim band is 0 (step 5's rim alone), as in Repair().
RepairResult RepairWithSteps(const ObjectCloud& input, const RepairConfig& config, const RepairSteps& steps,
                             const evidence::VisibilityRecord* record = nullptr);

}  // namespace graspfill::repair
