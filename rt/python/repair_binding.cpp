// SPDX-License-Identifier: BSD-3-Clause
// graspfill.repair(points, normals=None, up=None): the hole repair
// (repair/repairer.hpp, default RepairConfig: best mode) on numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.hpp"
#include "graspfill/repair/repairer.hpp"
#include "numpy_cloud.hpp"

namespace graspfill::python {
namespace py = pybind11;

namespace {

// The report as the CLI's `repair --json` gives it, plus the output normals
// when the input had some.
py::dict ReportToDict(const repair::RepairResult& result) {
  const repair::RepairReport& report = result.report;
  py::dict dict;
  dict["status"] = report.StatusText();
  dict["repaired"] = report.status == repair::RepairStatus::kRepaired;
  dict["symmetric"] = report.symmetric;
  dict["symmetry_reason"] = report.symmetry_reason;
  dict["top_completion"] = report.top_completion;
  dict["top_confidence"] = report.top_confidence;
  if (report.status == repair::RepairStatus::kRepaired) {
    const Eigen::Vector3d up = report.frame.T_in_V.linear().col(2);  // V's +z: towards the top
    dict["up_axis"] = py::make_tuple(up.x(), up.y(), up.z());
  }
  dict["outliers_ignored"] = report.outliers_ignored;
  dict["boundary_points"] = report.boundary_points;
  dict["boundary_lines"] = report.boundary_lines;
  dict["claw_holes_left_open"] = report.claw_holes_left_open;
  dict["holes"] = HolesToList(report.holes);
  py::dict timings;
  for (const StageTiming& timing : report.timings) timings[py::str(timing.stage)] = timing.ms;
  dict["timings_ms"] = std::move(timings);
  if (!result.cloud.normals_G.empty()) dict["normals"] = VectorsToArray(result.cloud.normals_G);
  return dict;
}

py::tuple RepairArrays(const py::handle& points, const py::handle& normals, const py::handle& up) {
  ObjectCloud input;
  input.points_G = VectorsFromArray(points, "points");
  if (!normals.is_none()) {
    input.normals_G = VectorsFromArray(normals, "normals");
    if (input.normals_G.size() != input.points_G.size()) {
      throw py::value_error("normals: expected one per point (" + std::to_string(input.points_G.size()) +
                            "), got " + std::to_string(input.normals_G.size()));
    }
  }
  repair::RepairConfig config;
  if (!up.is_none()) config.up_hint = DirectionFromSequence(up, "up");
  repair::RepairResult result;
  {
    py::gil_scoped_release release;  // ~0.1-1 s of C++ that touches no Python object
    result = repair::Repair(input, config);
  }
  return py::make_tuple(VectorsToArray(result.cloud.points_G), ProvenanceToArray(result.cloud),
                        ConfidenceToArray(result.cloud), ReportToDict(result));
}

}  // namespace

void BindRepair(py::module_& module) {
  module.def("repair", &RepairArrays, py::arg("points"), py::arg("normals") = py::none(),
             py::arg("up") = py::none(),
             R"doc(Fills the claw holes and the unseen top of an object cloud.

points: N x 3 float32 or float64 [m], any frame. normals: optional N x 3
(kept; the added points get estimated ones, in report["normals"]).
up: optional (x, y, z) hint of the direction to the missing top.

Returns (points, provenance, confidence, report): the input points first,
unchanged, then the added ones (float32 N' x 3); provenance uint8 (0
observed, 1 surface, 2 symmetry); confidence float32; report a dict with
status, repaired, top_completion, top_confidence, holes (dicts), timings_ms
and the rest of `graspfill repair --json`'s fields. A cloud too small, out
of range (e.g. in mm) or without holes comes back unchanged; report["status"]
says why. Raises ValueError for a bad shape, dtype or non-finite value.)doc");
}

}  // namespace graspfill::python
