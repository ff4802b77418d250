// SPDX-License-Identifier: GPL-3.0-or-later
// The compiled half of the Python package `ultratrack` (python/ultratrack/): one register_* function per bound
// area of the library, each in its own file, called once by module.cpp. Arguments arrive already shaped by the
// package's Python wrappers (python/ultratrack/__init__.py): paths as text, options as a dict of the command
// line's names with underscores. Bad input raises ultratrack.InputError with io::InputError's message.
#pragma once

#include <pybind11/pybind11.h>

#include <initializer_list>
#include <stop_token>
#include <string>

#include "io/input_error.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::python {

namespace py = pybind11;

void register_simulate(py::module_& m);  // bind_simulate.cpp: simulate
void register_receive(py::module_& m);   // bind_receive.cpp: receive
void register_acquire(py::module_& m);   // bind_acquire.cpp: acquire (file or numpy samples)
void register_fuse(py::module_& m);      // bind_fuse.cpp: fuse
void register_attitude(py::module_& m);  // bind_attitude.cpp: attitude
void register_snapshot(py::module_& m);  // bind_snapshot.cpp: snapshot
void register_align(py::module_& m);     // bind_align.cpp: align

// Takes `key` out of `options` (so that what is left over are unknown names), converted to T; false when absent.
template <typename T>
bool take_option(py::dict& options, const char* key, T& value) {
  if (!options.contains(key)) return false;
  value = options[key].cast<T>();
  PyDict_DelItemString(options.ptr(), key);
  return true;
}

// The value of an enum whose to_string(value) is `name`, among `values`; otherwise an InputError ("python") that
// lists the names, as the command line's messages do.
template <typename Enum, typename ToString>
Enum enum_from_name(const std::string& option, const std::string& name, std::initializer_list<Enum> values,
                    ToString to_string) {
  std::string names;
  for (const Enum v : values) {
    if (name == to_string(v)) return v;
    names += (names.empty() ? "" : ", ") + std::string(to_string(v));
  }
  throw io::InputError("python", option + " must be one of " + names + ", got '" + name + "'");
}

// The sample format named `format` (i8, i16, ...); otherwise an InputError ("python") that lists the names.
signals::SampleFormat sample_format_from_name(const std::string& format);

// An InputError naming `file` ("<what> file not found") unless it is a regular file.
void require_file(const std::string& file, const char* what);

// Raises TypeError naming the options left in `options` (none of `command`'s names).
void reject_unknown_options(const py::dict& options, const std::string& command);

// A stop token that a pending Ctrl-C (SIGINT) in the Python interpreter requests: call poll() from a progress
// callback (it takes the GIL for the check); after the run, rethrow() raises KeyboardInterrupt when it was hit.
class PythonInterrupt {
 public:
  std::stop_token token() const { return source_.get_token(); }
  void poll();
  void rethrow() const;

 private:
  std::stop_source source_;
  bool hit_ = false;
};

}  // namespace ultratrack::python
