// SPDX-License-Identifier: BSD-3-Clause
// graspfill.read_ply(path) and graspfill.write_ply(path, points, ...):
// graspfill's own cloud files (io/cloud_file.hpp), so that a file written
// from Python is the CLI's to the byte.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>

#include "bindings.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "numpy_cloud.hpp"

namespace graspfill::python {
namespace py = pybind11;

namespace {

py::dict ReadCloud(const std::filesystem::path& path) {
  ObjectCloud cloud;
  {
    py::gil_scoped_release release;
    cloud = io::ReadCloudFile(path.string());  // throws naming the path
  }
  return CloudToDict(cloud);
}

void WriteCloud(const std::filesystem::path& path, const py::handle& points, const py::handle& provenance,
                const py::handle& confidence, const py::handle& normals) {
  ObjectCloud cloud;
  cloud.points_G = VectorsFromArray(points, "points");
  const size_t n = cloud.points_G.size();
  if (!provenance.is_none()) cloud.provenance = ProvenanceFromArray(provenance, n);
  if (!confidence.is_none()) cloud.confidence = ConfidenceFromArray(confidence, n);
  if (!normals.is_none()) {
    cloud.normals_G = VectorsFromArray(normals, "normals");
    if (cloud.normals_G.size() != n) {
      throw py::value_error("normals: expected one per point (" + std::to_string(n) + "), got " +
                            std::to_string(cloud.normals_G.size()));
    }
  }
  py::gil_scoped_release release;
  io::WriteCloudFile(path.string(), cloud);  // .ply or .pcd by the name; anything else refused
}

}  // namespace

void BindCloudFiles(py::module_& module) {
  module.def("read_ply", &ReadCloud, py::arg("path"),
             R"doc(Reads a point cloud PLY (any PLY Open3D reads) as a dict of numpy arrays.

Keys: points (float32 N x 3), normals (float32 N x 3, or None), provenance
(uint8, 0 where the file has none), confidence (float32, 1 where the file
has none), and graspfill's header fields: frame_name, utime, seq, T_C_G
(4 x 4). Raises RuntimeError naming the path for a missing or malformed
file, ValueError for a .pcd (not read: convert it to PLY).)doc");
  module.def("write_ply", &WriteCloud, py::arg("path"), py::arg("points"), py::arg("provenance") = py::none(),
             py::arg("confidence") = py::none(), py::arg("normals") = py::none(),
             R"doc(Writes a cloud as graspfill's binary PLY (or PCD when the path ends in .pcd).

points: N x 3 float32 or float64 [m]; provenance: N integers 0..2;
confidence: N floats in [0, 1]; normals: N x 3. The file is replaced
atomically. Raises ValueError for bad arrays or another extension,
RuntimeError naming the path when it cannot be written.)doc");
}

}  // namespace graspfill::python
