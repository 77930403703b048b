// SPDX-License-Identifier: BSD-3-Clause
// graspfill.Subscriber: object_cloud_t clouds from a live LCM bus as dicts
// (CloudSubscriber), waited for with the GIL released, in short slices so
// that Ctrl-C and other Python signals are seen while waiting.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // std::optional <-> None

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "cloud_subscriber.hpp"
#include "numpy_cloud.hpp"

namespace graspfill::python {
namespace py = pybind11;

namespace {

// The longest wait without a look at Python's signals.
constexpr int kWaitSliceMs = 100;

class PySubscriber {
 public:
  PySubscriber(std::string channel, std::string url)
      : channel_(std::move(channel)), url_(std::move(url)), subscriber_(url_, channel_) {}

  // The next cloud, or None once `timeout_s` passed (None: wait for ever).
  // @throws EOFError once LCM ended (a log's end, or the bus failed).
  py::object Next(std::optional<double> timeout_s) {
    bool ended = false;
    py::object cloud = Take(timeout_s, &ended);
    if (ended) {
      PyErr_SetString(PyExc_EOFError, "Subscriber: LCM ended (a file:// log's end, or the bus failed)");
      throw py::error_already_set();
    }
    return cloud;
  }

  // Iteration: the next cloud, waited for as long as it takes; a log's end stops it.
  py::object NextInLoop() {
    bool ended = false;
    py::object cloud = Take(std::nullopt, &ended);
    if (ended) throw py::stop_iteration();
    return cloud;
  }

  void Close() { subscriber_.Close(); }
  const std::string& channel() const { return channel_; }
  const std::string& url() const { return url_; }
  int64_t bad_messages() const { return subscriber_.bad_messages(); }
  const std::string& last_error() const { return last_error_; }

 private:
  // A cloud as a dict, or None after `timeout_s`, or None and *ended once
  // LCM ended.
  py::object Take(std::optional<double> timeout_s, bool* ended) {
    if (timeout_s && !(*timeout_s >= 0.0)) {  // NaN fails too
      throw py::value_error("timeout_s: expected a number >= 0 or None, got " + std::to_string(*timeout_s));
    }
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    while (true) {
      if (subscriber_.closed()) throw py::value_error("Subscriber: closed");
      int slice_ms = kWaitSliceMs;
      if (timeout_s) {
        const double left_ms =
            *timeout_s * 1e3 - std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        slice_ms = static_cast<int>(std::ceil(std::max(0.0, std::min<double>(left_ms, kWaitSliceMs))));
      }
      ObjectCloud cloud;
      std::string error;
      CloudSubscriber::WaitResult result;
      {
        py::gil_scoped_release release;
        result = subscriber_.Wait(slice_ms, &cloud, &error);
      }
      switch (result) {
        case CloudSubscriber::WaitResult::kCloud:
          return CloudToDict(cloud);
        case CloudSubscriber::WaitResult::kEnded:
          *ended = true;
          return py::none();
        case CloudSubscriber::WaitResult::kBadMessage:
          last_error_ = error;
          break;
        case CloudSubscriber::WaitResult::kTimeout:
          if (slice_ms == 0) return py::none();  // timeout_s passed (or was 0): one look taken
          break;
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (timeout_s && Clock::now() - start >= std::chrono::duration<double>(*timeout_s)) return py::none();
    }
  }

  std::string channel_;
  std::string url_;
  CloudSubscriber subscriber_;
  std::string last_error_;
};

}  // namespace

void BindSubscriber(py::module_& module) {
  py::class_<PySubscriber>(module, "Subscriber", R"doc(object_cloud_t clouds from a live LCM bus, as dicts.

Subscriber(channel="GRASPFILL_OBJECT_CLOUD", url=""): url "" is LCM's default
(LCM_DEFAULT_URL, else UDP multicast), where each cloud comes as
one-datagram slices (object_cloud_chunk_t) that are joined here; a log's
whole object_cloud_t messages are taken as they are.
next(timeout_s=None) gives the next cloud (decode_object_cloud's dict) or
None after timeout_s seconds, and raises EOFError once LCM ended (a file://
log's end, or the bus failed); iterating waits for ever and stops there.
Messages that do not decode are skipped and counted (bad_messages,
last_error). Use it from one
thread at a time; close() or a `with` block releases the socket.)doc")
      .def(py::init<std::string, std::string>(), py::arg("channel") = "GRASPFILL_OBJECT_CLOUD",
           py::arg("url") = "")
      .def("next", &PySubscriber::Next, py::arg("timeout_s") = py::none(),
           "The next cloud as a dict, or None when timeout_s seconds passed (None: wait for ever); "
           "EOFError once LCM ended.")
      .def("__iter__", [](PySubscriber& self) -> PySubscriber& { return self; })
      .def("__next__", &PySubscriber::NextInLoop)
      .def("close", &PySubscriber::Close, "Unsubscribes and closes the LCM instance.")
      .def("__enter__", [](PySubscriber& self) -> PySubscriber& { return self; })
      .def("__exit__", [](PySubscriber& self, const py::args&) { self.Close(); })
      .def_property_readonly("channel", &PySubscriber::channel)
      .def_property_readonly("url", &PySubscriber::url)
      .def_property_readonly("bad_messages", &PySubscriber::bad_messages,
                             "Messages that did not decode (skipped).")
      .def_property_readonly("last_error", &PySubscriber::last_error,
                             "Why the last skipped message did not decode.");
}

}  // namespace graspfill::python
