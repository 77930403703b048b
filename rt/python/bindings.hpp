// SPDX-License-Identifier: BSD-3-Clause
// The parts of the Python module `graspfill._native` (module.cpp puts them
// together); each adds its functions or class to `module`.
#pragma once

#include <pybind11/pybind11.h>

namespace graspfill::python {

/// repair(points, normals=None, up=None) (repair_binding.cpp).
void BindRepair(pybind11::module_& module);
/// read_ply(path), write_ply(path, points, ...) (ply_binding.cpp).
void BindCloudFiles(pybind11::module_& module);
/// decode_object_cloud(data) (message_binding.cpp).
void BindMessages(pybind11::module_& module);
/// class Subscriber (subscriber_binding.cpp).
void BindSubscriber(pybind11::module_& module);

}  // namespace graspfill::python
