// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.attitude: the multi-antenna receiver on one recording per antenna (pipelines/attitude_file.hpp) with
// `ultratrack attitude`'s settings under its names; the array from an antenna file (config/antenna_config_toml.hpp).
// Returns the run's statistics as a dict.
#include <pybind11/stl.h>

#include <filesystem>
#include <vector>

#include "bindings.hpp"
#include "config/antenna_config_toml.hpp"
#include "pipelines/attitude_file.hpp"
#include "receiver/receiver_summary.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::python {

namespace {

py::dict attitude(const std::vector<std::string>& inputs, const std::string& format, double fs_hz, double if_hz,
                  const std::string& antennas_file, const std::string& nav, const std::string& out, py::dict options) {
  const signals::SampleFormat sample_format = sample_format_from_name(format);
  const config::AntennaConfig antennas = config::read_antenna_config(antennas_file);
  const auto n_ant = antennas.solver.array.lever_arm_body_m.size();
  if (inputs.size() != n_ant)
    throw io::InputError("python", "input: " + std::to_string(inputs.size()) + " files for the " +
                                       std::to_string(n_ant) + " antennas of " + antennas_file);
  pipelines::AttitudeFileJob job;
  job.inputs.assign(inputs.begin(), inputs.end());
  job.format = sample_format;
  job.solver = antennas.solver;
  job.line_bias_cycles = antennas.line_bias_cycles;
  job.out = out;
  job.source.fs_hz = fs_hz;
  job.source.if_hz = if_hz;
  receiver::ReceiverOptions& r = job.options;
  r.fs_hz = fs_hz;
  take_option(options, "prn", r.prns);
  take_option(options, "threads", r.threads);
  take_option(options, "interval", r.observation_interval_s);
  take_option(options, "duration", job.duration_s);
  if (!nav.empty()) job.navigation = signals::read_rinex_nav(nav);
  if (take_option(options, "reference_week", r.reference_week)) r.reference_week_is_signal_week = true;  // else nav's
  reject_unknown_options(options, "attitude");

  PythonInterrupt interrupt;
  pipelines::AttitudeFileResult result;
  {
    py::gil_scoped_release release;
    result = pipelines::attitude_file(
        std::move(job), interrupt.token(),
        [&](const receiver::ReceiverEngine&, const receiver::AttitudeStats&) { interrupt.poll(); });
  }
  interrupt.rethrow();
  const receiver::AttitudeStats& s = result.stats;
  py::dict d;
  d["out"] = out;
  d["antennas"] = n_ant;
  d["processed_s"] = result.processed_s;
  d["wall_s"] = result.wall_s;
  d["threads"] = result.threads;
  d["interrupted"] = result.interrupted;
  d["epochs"] = s.epochs;
  d["attitude_epochs"] = s.attitude_epochs;
  d["fixed_epochs"] = s.fixed_epochs;
  d["fix_rate"] = s.epochs ? static_cast<double>(s.fixed_epochs) / s.epochs : 0.0;
  return d;
}

}  // namespace

void register_attitude(py::module_& m) {
  m.def("_attitude", &attitude, py::arg("inputs"), py::arg("format"), py::arg("fs"), py::arg("if_hz"),
        py::arg("antennas"), py::arg("nav"), py::arg("out"), py::arg("options"));
}

}  // namespace ultratrack::python
