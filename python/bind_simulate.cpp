// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.simulate: a scenario (a TOML file, or its text) simulated into a folder as `ultratrack simulate`
// writes it (sim/simulation_files.hpp), scenario.toml being the scenario with every key (config::to_toml).
#include <pybind11/stl.h>

#include <filesystem>

#include "bindings.hpp"
#include "config/scenario_toml.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::python {

namespace {

py::dict simulate(const std::string& scenario_file, const std::string& scenario_text, const std::string& out) {
  const sim::Scenario scenario =
      scenario_text.empty()
          ? config::read_scenario(scenario_file)
          : config::parse_scenario(scenario_text, scenario_file.empty() ? "scenario text" : scenario_file);
  PythonInterrupt interrupt;
  sim::SimulationResult r;
  {
    py::gil_scoped_release release;
    r = sim::simulate_to_folder(scenario, out, config::to_toml(scenario), interrupt.token(),
                                [&](const sim::SimulationProgress&) { interrupt.poll(); });
  }
  interrupt.rethrow();
  py::list satellites;
  for (const auto& v : r.satellites) {
    py::dict s;
    s["prn"] = v.prn;
    s["elevation_deg"] = v.elevation_rad * 180.0 / M_PI;
    s["azimuth_deg"] = v.azimuth_rad * 180.0 / M_PI;
    s["cn0_dbhz"] = v.cn0_dbhz;
    s["doppler_hz"] = v.doppler_hz;
    s["code_phase_chips"] = v.code_phase_chips;
    satellites.append(s);
  }
  py::list files;
  for (const auto& f : r.sample_files) files.append(f.string());
  py::dict d;
  d["out"] = out;
  d["navigation"] = r.navigation;
  d["antennas"] = r.antennas;
  d["samples"] = r.samples;
  d["signal_s"] = r.signal_s;
  d["wall_s"] = r.wall_s;
  d["noise_sigma"] = r.noise_sigma;
  d["interrupted"] = r.interrupted;
  d["truth_rows"] = r.truth_rows;
  d["imu_rows"] = r.imu_rows;
  d["sample_files"] = files;
  d["satellites"] = satellites;
  d["format"] = std::string(signals::to_string(scenario.format));
  d["fs_hz"] = scenario.sample_rate_hz;
  d["if_hz"] = scenario.if_hz;
  return d;
}

}  // namespace

void register_simulate(py::module_& m) {
  m.def("_simulate", &simulate, py::arg("scenario_file"), py::arg("scenario_text"), py::arg("out"));
}

}  // namespace ultratrack::python
