// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.fuse: loosely coupled GNSS/INS from an IMU CSV and a GNSS fix CSV (pipelines/fuse.hpp) into
// out/nav.csv and out/summary.json, with `ultratrack fuse`'s settings under its names. Returns summary.json's text
// (the Python wrapper reads it into a dict).
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "config/fuse_config_toml.hpp"
#include "ins/imu_csv.hpp"
#include "io/atomic_file.hpp"
#include "pipelines/fuse.hpp"
#include "pipelines/fuse_summary.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "sim/truth_csv.hpp"

namespace ultratrack::python {

namespace {

namespace fs = std::filesystem;

std::string fuse(const std::string& imu_file, const std::string& gnss_file, const std::string& out,
                 const std::string& truth_file, const std::string& filter, const std::string& align,
                 const std::string& config_file, const std::vector<std::pair<double, double>>& outages,
                 const std::string& attitude_file, const std::optional<std::pair<int, double>>& attitude_origin,
                 int decimate) {
  pipelines::FuseSettings s;
  s.filter = enum_from_name("filter", filter, {fusion::FilterKind::Ekf, fusion::FilterKind::Ukf},
                            [](fusion::FilterKind f) { return f == fusion::FilterKind::Ekf ? "ekf" : "ukf"; });
  s.align = enum_from_name("align", align,
                           {pipelines::AlignMode::Static, pipelines::AlignMode::Motion, pipelines::AlignMode::Config,
                            pipelines::AlignMode::Attitude},
                           [](pipelines::AlignMode a) { return pipelines::to_string(a); });
  if (decimate < 1) throw io::InputError("python", "decimate must be at least 1");
  for (const auto& [start, duration] : outages) {
    if (!(duration > 0.0)) throw io::InputError("python", "outage duration must be positive");
    s.outages.emplace_back(start, duration);
  }
  if (!config_file.empty()) {
    require_file(config_file, "configuration");
    s.config = config::read_fuse_config(config_file);
  }
  if (attitude_origin) {
    const auto [week, tow] = *attitude_origin;
    if (week < 0 || !(tow >= 0.0 && tow < 604800.0))
      throw io::InputError("python", "attitude_origin takes (WEEK, TOW): TOW in [0, 604800) s");
    s.config.attitude_gps_time_at_imu_zero = signals::GpsTime{week, tow};
  }
  if (!attitude_file.empty()) {
    require_file(attitude_file, "attitude");
    s.attitude = pipelines::read_attitude_csv(attitude_file);
    s.attitude_file = attitude_file;
  }
  require_file(imu_file, "IMU");
  require_file(gnss_file, "GNSS");
  const auto imu = ins::read_imu_csv(imu_file);
  const auto gnss = pipelines::read_gnss_csv(gnss_file);
  std::vector<ins::NavState> truth;
  if (!truth_file.empty()) {
    require_file(truth_file, "truth");
    truth = sim::read_truth_csv(truth_file);
  }

  fs::create_directories(out);
  PythonInterrupt interrupt;
  std::string summary;
  {
    py::gil_scoped_release release;
    pipelines::FusedNavCsvWriter nav(fs::path(out) / "nav.csv");
    long long rows = 0;
    const pipelines::FuseResult r = pipelines::fuse(
        imu, gnss, pipelines::truth_samples_from_nav(truth), s,
        [&](const ins::NavState& state, const pipelines::NavSigma& sigma) {
          if (rows++ % decimate == 0) nav.write(state, sigma);
        },
        [&](double) { interrupt.poll(); }, interrupt.token());
    nav.commit();
    summary = pipelines::fuse_summary_json(r, s, imu_file, gnss_file, truth_file);
    io::write_file_atomically(fs::path(out) / "summary.json", summary);
  }
  interrupt.rethrow();
  return summary;
}

}  // namespace

void register_fuse(py::module_& m) {
  m.def("_fuse", &fuse, py::arg("imu"), py::arg("gnss"), py::arg("out"), py::arg("truth"), py::arg("filter"),
        py::arg("align"), py::arg("config"), py::arg("outage"), py::arg("attitude"), py::arg("attitude_origin"),
        py::arg("decimate"));
}

}  // namespace ultratrack::python
