// SPDX-License-Identifier: BSD-3-Clause
#include "numpy_cloud.hpp"

#include <cmath>
#include <cstring>
#include <string>

namespace graspfill::python {
namespace py = pybind11;

namespace {

static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float),
              "vectors are copied to and from numpy as packed float triples");

// "(4, 2)", "(7,)": numpy's own way of writing a shape.
std::string ShapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d) {
    if (d > 0) text += ", ";
    text += std::to_string(array.shape(d));
  }
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string DtypeText(const py::array& array) { return py::str(array.dtype()).cast<std::string>(); }

// Any array-like (a list of lists too) as an array; ValueError otherwise.
py::array AsArray(const py::handle& object, const std::string& name) {
  py::array array = py::array::ensure(object);
  if (!array)
    throw py::value_error(name + ": expected a numpy array, got " +
                          py::str(py::type::of(object)).cast<std::string>());
  return array;
}

py::array AsVector(const py::handle& object, const std::string& name, size_t size) {
  py::array array = AsArray(object, name);
  if (array.ndim() != 1 || static_cast<size_t>(array.shape(0)) != size) {
    throw py::value_error(name + ": expected shape (" + std::to_string(size) +
                          ",) (one per point), got shape " + ShapeText(array));
  }
  return array;
}

template <typename Scalar>
std::vector<Eigen::Vector3f> CopyRows(const py::array& array, const std::string& name) {
  const auto rows = array.unchecked<Scalar, 2>();  // reads through any strides
  std::vector<Eigen::Vector3f> vectors(static_cast<size_t>(rows.shape(0)));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    for (int k = 0; k < 3; ++k) {
      // A float64 beyond float32's range is not finite after the cast.
      const float value = static_cast<float>(rows(i, k));
      if (!std::isfinite(value)) {
        throw py::value_error(name + ": row " + std::to_string(i) +
                              " is not finite in float32 (NaN, inf or beyond 3.4e38)");
      }
      vectors[static_cast<size_t>(i)][k] = value;
    }
  }
  return vectors;
}

}  // namespace

std::vector<Eigen::Vector3f> VectorsFromArray(const py::handle& object, const char* name) {
  const py::array array = AsArray(object, name);
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw py::value_error(std::string(name) + ": expected an N x 3 array, got shape " + ShapeText(array));
  }
  if (py::isinstance<py::array_t<float>>(array)) return CopyRows<float>(array, name);
  if (py::isinstance<py::array_t<double>>(array)) return CopyRows<double>(array, name);
  throw py::value_error(std::string(name) + ": expected float32 or float64, got " + DtypeText(array));
}

std::vector<Provenance> ProvenanceFromArray(const py::handle& object, size_t num_points) {
  const py::array array = AsVector(object, "provenance", num_points);
  const char kind = array.dtype().kind();
  if (kind != 'u' && kind != 'i') {
    throw py::value_error("provenance: expected integers (uint8), got " + DtypeText(array));
  }
  // Kept while `values` reads it (unchecked() does not own the data).
  const auto converted = py::array_t<int64_t, py::array::forcecast>::ensure(array);
  const auto values = converted.unchecked<1>();
  std::vector<Provenance> provenance(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    const int64_t value = values(static_cast<py::ssize_t>(i));
    if (value < 0 || value > 2) {
      throw py::value_error("provenance: value " + std::to_string(value) + " at " + std::to_string(i) +
                            " is not 0 (observed), 1 (surface) or 2 (symmetry)");
    }
    provenance[i] = static_cast<Provenance>(value);
  }
  return provenance;
}

std::vector<float> ConfidenceFromArray(const py::handle& object, size_t num_points) {
  const py::array array = AsVector(object, "confidence", num_points);
  if (array.dtype().kind() != 'f') {
    throw py::value_error("confidence: expected floats (float32), got " + DtypeText(array));
  }
  const auto converted = py::array_t<float, py::array::forcecast>::ensure(array);
  const auto values = converted.unchecked<1>();
  std::vector<float> confidence(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    const float value = values(static_cast<py::ssize_t>(i));
    if (!(value >= 0.0f && value <= 1.0f)) {  // NaN fails too
      throw py::value_error("confidence: value " + std::to_string(value) + " at " + std::to_string(i) +
                            " is not in [0, 1]");
    }
    confidence[i] = value;
  }
  return confidence;
}

Eigen::Vector3d DirectionFromSequence(const py::handle& object, const char* name) {
  const auto array = py::array_t<double, py::array::forcecast>::ensure(object);
  if (!array || array.ndim() != 1 || array.shape(0) != 3) {
    throw py::value_error(std::string(name) + ": expected three numbers (x, y, z)");
  }
  const Eigen::Vector3d direction(array.at(0), array.at(1), array.at(2));
  if (!direction.allFinite() || direction.norm() == 0.0) {
    throw py::value_error(std::string(name) + ": expected a finite, non-zero direction");
  }
  return direction.normalized();
}

py::array_t<float> VectorsToArray(const std::vector<Eigen::Vector3f>& vectors) {
  py::array_t<float> array({static_cast<py::ssize_t>(vectors.size()), py::ssize_t{3}});
  if (!vectors.empty())
    std::memcpy(array.mutable_data(), vectors.data(), vectors.size() * sizeof(vectors[0]));
  return array;
}

py::array_t<uint8_t> ProvenanceToArray(const ObjectCloud& cloud) {
  py::array_t<uint8_t> array(static_cast<py::ssize_t>(cloud.size()));
  uint8_t* out = array.mutable_data();
  for (size_t i = 0; i < cloud.size(); ++i) {
    out[i] = cloud.provenance.empty() ? static_cast<uint8_t>(Provenance::kObserved)
                                      : static_cast<uint8_t>(cloud.provenance[i]);
  }
  return array;
}

py::array_t<float> ConfidenceToArray(const ObjectCloud& cloud) {
  py::array_t<float> array(static_cast<py::ssize_t>(cloud.size()));
  float* out = array.mutable_data();
  for (size_t i = 0; i < cloud.size(); ++i) {
    out[i] = cloud.confidence.empty() ? 1.0f : cloud.confidence[i];
  }
  return array;
}

py::list HolesToList(const std::vector<HoleSummary>& holes) {
  py::list list;
  for (const HoleSummary& hole : holes) {
    py::dict entry;
    entry["kind"] = hole.kind == HoleKind::kClaw ? "claw" : "missing_surface";
    entry["boundary_points"] = hole.boundary_points;
    entry["box_min"] = py::make_tuple(hole.box_min_G.x(), hole.box_min_G.y(), hole.box_min_G.z());
    entry["box_max"] = py::make_tuple(hole.box_max_G.x(), hole.box_max_G.y(), hole.box_max_G.z());
    entry["points_added"] = hole.points_added;
    entry["unobserved"] = hole.unobserved;
    entry["confidence"] = hole.confidence;
    list.append(std::move(entry));
  }
  return list;
}

namespace {

py::object SafeBoundToDict(const SafeBound& bound) {
  if (bound.empty()) return py::none();
  py::array_t<bool> occupied({static_cast<py::ssize_t>(bound.nx), static_cast<py::ssize_t>(bound.ny),
                              static_cast<py::ssize_t>(bound.nz)});
  auto cells = occupied.mutable_unchecked<3>();
  for (int i = 0; i < bound.nx; ++i) {
    for (int j = 0; j < bound.ny; ++j) {
      for (int k = 0; k < bound.nz; ++k) cells(i, j, k) = bound.Occupied(i, j, k);
    }
  }
  py::dict dict;
  dict["origin"] = py::make_tuple(bound.origin_G.x(), bound.origin_G.y(), bound.origin_G.z());
  dict["voxel_m"] = bound.voxel_m;
  dict["occupied"] = std::move(occupied);
  return std::move(dict);
}

py::array_t<double> PoseToArray(const Eigen::Isometry3d& T) {
  py::array_t<double> array({py::ssize_t{4}, py::ssize_t{4}});
  auto cells = array.mutable_unchecked<2>();
  const Eigen::Matrix4d matrix = T.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) cells(r, c) = matrix(r, c);
  }
  return array;
}

}  // namespace

py::dict CloudToDict(const ObjectCloud& cloud) {
  py::dict dict;
  dict["points"] = VectorsToArray(cloud.points_G);
  dict["normals"] = cloud.normals_G.empty() ? py::object(py::none()) : VectorsToArray(cloud.normals_G);
  dict["provenance"] = ProvenanceToArray(cloud);
  dict["confidence"] = ConfidenceToArray(cloud);
  dict["holes"] = HolesToList(cloud.holes);
  dict["safe_bound"] = SafeBoundToDict(cloud.safe_bound);
  py::dict timings;
  for (const StageTiming& timing : cloud.timings) timings[py::str(timing.stage)] = timing.ms;
  dict["timings_ms"] = std::move(timings);
  dict["utime"] = cloud.utime;
  dict["seq"] = cloud.seq;
  dict["frame_name"] = cloud.frame_name;
  dict["grasp_id"] = cloud.grasp_id;
  dict["is_final"] = cloud.is_final;
  dict["T_C_G"] = PoseToArray(cloud.T_C_G);
  return dict;
}

}  // namespace graspfill::python
