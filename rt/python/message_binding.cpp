// SPDX-License-Identifier: BSD-3-Clause
// graspfill.decode_object_cloud(data): object_cloud_t bytes to numpy,
// through graspfill's own decoder (io/messages.hpp), so the module reads
// whatever encoding the C++ side reads.
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.hpp"
#include "graspfill/io/messages.hpp"
#include "numpy_cloud.hpp"

namespace graspfill::python {
namespace py = pybind11;

namespace {

py::dict DecodeCloud(const py::buffer& data) {
  const py::buffer_info bytes = data.request();
  if (bytes.ndim != 1 || bytes.strides[0] != bytes.itemsize) {
    throw py::value_error("decode_object_cloud: expected contiguous bytes (bytes, bytearray, memoryview)");
  }
  ObjectCloud cloud;
  std::string error;
  io::MessageError reason = io::MessageError::kNone;
  bool decoded = false;
  {
    py::gil_scoped_release release;  // `data` keeps the buffer alive meanwhile
    decoded = io::DecodeObjectCloud(bytes.ptr, static_cast<size_t>(bytes.size * bytes.itemsize), &cloud,
                                    &error, &reason);
  }
  if (!decoded) {
    // The decoder's text names the type ("object_cloud_t: ...").
    throw py::value_error(error + " (" + io::MessageErrorName(reason) + ")");
  }
  return CloudToDict(cloud);
}

}  // namespace

void BindMessages(py::module_& module) {
  module.def("decode_object_cloud", &DecodeCloud, py::arg("data"),
             R"doc(Decodes one object_cloud_t message (an LCM payload) into a dict.

Keys: points, normals (or None), provenance, confidence, holes (dicts),
safe_bound (None, or origin, voxel_m and `occupied`, a bool array indexed
[i, j, k]), timings_ms, utime, seq, frame_name, grasp_id, is_final and
T_C_G (4 x 4: maps points from the gripper frame G to the camera's).
Raises ValueError with the decoder's reason for bytes that do not decode.)doc");
}

}  // namespace graspfill::python
