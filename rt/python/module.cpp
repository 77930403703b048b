// SPDX-License-Identifier: BSD-3-Clause
// The Python module `graspfill._native`: graspfill's repair, cloud files,
// message decoding and a live LCM subscriber for planners in Python. The
// package `graspfill` re-exports it beside lcm-gen's message classes
// (rt/python/package_init.py); docs/planner-bindings.md documents it.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_native, module) {
  module.doc() =
      "graspfill's C++ core for Python: repair() on numpy arrays, read_ply()/write_ply(), "
      "decode_object_cloud() and Subscriber (object_cloud_t over LCM). Points are float32 "
      "N x 3 in meters; provenance uint8 (0 observed, 1 surface, 2 symmetry); confidence float32.";
  graspfill::python::BindRepair(module);
  graspfill::python::BindCloudFiles(module);
  graspfill::python::BindMessages(module);
  graspfill::python::BindSubscriber(module);
}
