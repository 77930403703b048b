// SPDX-License-Identifier: BSD-3-Clause
// Conversions between numpy arrays and graspfill's ObjectCloud, shared by
// every function of the Python module. Python callers get ValueError, with
// the argument's name and what was wrong, for anything the C++ side would
// misread; nothing here may crash on a bad array.
//
// Call with the GIL held (they create or read Python objects).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::python {

/// An N x 3 array of float32 or float64 (any strides) as float vectors.
/// @param name  the argument's name, for the error message.
/// @throws pybind11::value_error naming the shape or dtype, or the first
///   row that is not finite (also a float64 beyond float32's range).
std::vector<Eigen::Vector3f> VectorsFromArray(const pybind11::handle& array, const char* name);

/// N uint8-convertible provenance values, each 0 (observed), 1 (surface)
/// or 2 (symmetry). @throws pybind11::value_error otherwise.
std::vector<Provenance> ProvenanceFromArray(const pybind11::handle& array, size_t num_points);

/// N confidences, each finite in [0, 1]. @throws pybind11::value_error otherwise.
std::vector<float> ConfidenceFromArray(const pybind11::handle& array, size_t num_points);

/// A direction of three finite numbers, not all 0, normalized.
/// @throws pybind11::value_error otherwise.
Eigen::Vector3d DirectionFromSequence(const pybind11::handle& sequence, const char* name);

/// Float vectors as a new N x 3 float32 array.
pybind11::array_t<float> VectorsToArray(const std::vector<Eigen::Vector3f>& vectors);

/// The cloud's per-point arrays: provenance (uint8, kObserved where the
/// cloud has none) and confidence (float32, 1 where the cloud has none).
pybind11::array_t<uint8_t> ProvenanceToArray(const ObjectCloud& cloud);
pybind11::array_t<float> ConfidenceToArray(const ObjectCloud& cloud);

/// One dict per hole: kind ("claw" | "missing_surface"), boundary_points,
/// box_min, box_max (in the cloud's frame [m]), points_added, unobserved,
/// confidence.
pybind11::list HolesToList(const std::vector<HoleSummary>& holes);

/// Every field of the cloud: points, normals (None when it has none),
/// provenance, confidence, holes, safe_bound (None when empty; else origin,
/// voxel_m and `occupied`, a bool array indexed [i, j, k]), timings_ms,
/// utime, seq, frame_name, grasp_id, is_final and T_C_G (4 x 4 float64).
pybind11::dict CloudToDict(const ObjectCloud& cloud);

}  // namespace graspfill::python
