// SPDX-License-Identifier: GPL-3.0-or-later
// The extension module ultratrack._ultratrack: the library's entry points for Python (python/bindings.hpp),
// io::InputError translated to ultratrack.InputError (a ValueError) with the same message.
#include <pybind11/pybind11.h>

#include <filesystem>

#include "bindings.hpp"
#include "io/input_error.hpp"

namespace ultratrack::python {

signals::SampleFormat sample_format_from_name(const std::string& format) {
  const auto sample_format = signals::parse_sample_format(format);
  if (!sample_format)
    throw io::InputError("python", "format: unknown sample format '" + format + "' (" +
                                       std::string(signals::sample_format_names()) + ")");
  return *sample_format;
}

void require_file(const std::string& file, const char* what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw io::InputError(file, std::string(what) + " file not found");
}

void reject_unknown_options(const py::dict& options, const std::string& command) {
  if (options.empty()) return;
  std::string names;
  for (const auto& item : options) names += (names.empty() ? "" : ", ") + py::str(item.first).cast<std::string>();
  throw py::type_error(command + ": unknown option(s) " + names);
}

void PythonInterrupt::poll() {
  if (hit_) return;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) {
    PyErr_Clear();  // raised again by rethrow() once the run has finished its files
    hit_ = true;
    source_.request_stop();
  }
}

void PythonInterrupt::rethrow() const {
  if (!hit_) return;
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw py::error_already_set();
}

}  // namespace ultratrack::python

PYBIND11_MODULE(_ultratrack, m) {
  namespace up = ultratrack::python;
  m.doc() = "Ultratrack's library (pipelines, sim, config) for Python; use the package `ultratrack`.";
  pybind11::register_exception<ultratrack::io::InputError>(m, "InputError", PyExc_ValueError);
  up::register_simulate(m);
  up::register_receive(m);
  up::register_acquire(m);
  up::register_fuse(m);
  up::register_attitude(m);
  up::register_snapshot(m);
  up::register_align(m);
}
