// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.align: the stationary fine alignment from an IMU at rest and a multi-antenna receiver's attitude.csv
// (pipelines/alignment_run.hpp) with `ultratrack align`'s settings under its names, into out/alignment.json and
// out/alignment.csv as the command writes them. Returns alignment.json's text (the Python wrapper reads it into a
// dict).
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
#include "pipelines/alignment_run.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "pipelines/pps_time_sync.hpp"

namespace ultratrack::python {

namespace {

namespace fs = std::filesystem;

std::string align(const std::string& imu_file, const std::string& attitude_file, const std::string& out,
                  const std::string& config_file, const std::optional<std::vector<double>>& position,
                  const std::optional<std::pair<int, double>>& attitude_origin, const std::string& pps_file,
                  const std::optional<std::vector<double>>& reference, double duration_s, double interval_s,
                  const std::string& filter) {
  pipelines::AlignSettings s;
  s.filter = enum_from_name("filter", filter, {fusion::FilterKind::Ekf, fusion::FilterKind::Ukf},
                            [](fusion::FilterKind f) { return f == fusion::FilterKind::Ekf ? "ekf" : "ukf"; });
  if (!(duration_s >= 0.0)) throw io::InputError("python", "duration must be >= 0 (0: all the data)");
  if (!(interval_s > 0.0)) throw io::InputError("python", "filter_interval must be positive");
  s.duration_s = duration_s;
  s.filter_interval_s = interval_s;
  s.imu_file = imu_file;
  s.attitude_file = attitude_file;
  require_file(imu_file, "IMU");
  require_file(attitude_file, "attitude");
  if (!config_file.empty()) {
    require_file(config_file, "configuration");
    s.config = config::read_fuse_config(config_file);
  }
  if (position) {
    const std::vector<double>& p = *position;
    if (p.size() != 3 || !(std::abs(p[0]) <= 90.0 && std::abs(p[1]) <= 360.0) || !std::isfinite(p[2]))
      throw io::InputError("python", "position takes (LAT_DEG, LON_DEG, HEIGHT_M)");
    s.config.position_deg_m = Eigen::Vector3d(p[0], p[1], p[2]);
  }
  if (attitude_origin) {
    const auto [week, tow] = *attitude_origin;
    if (week < 0 || !(tow >= 0.0 && tow < 604800.0))
      throw io::InputError("python", "attitude_origin takes (WEEK, TOW): TOW in [0, 604800) s");
    s.config.attitude_gps_time_at_imu_zero = signals::GpsTime{week, tow};
  }
  if (reference) {
    const std::vector<double>& v = *reference;
    const double d = M_PI / 180.0;
    if (v.size() != 6 || !(std::abs(v[0]) <= 180.0 && std::abs(v[1]) < 90.0 && std::abs(v[2]) <= 360.0 && v[3] > 0.0 &&
                           v[4] > 0.0 && v[5] > 0.0 && std::isfinite(v[3] + v[4] + v[5])))
      throw io::InputError("python", "reference_attitude takes (ROLL, PITCH, YAW, their positive 1-sigmas), deg");
    s.reference_attitude = ins::EulerAngles{v[0] * d, v[1] * d, v[2] * d};
    s.reference_sigma_rad = Eigen::Vector3d(v[3], v[4], v[5]) * d;
  }

  const auto attitude = pipelines::read_attitude_csv(attitude_file);
  auto imu = ins::read_imu_csv(imu_file, {s.config.imu_max_gap_s});
  if (!pps_file.empty()) {
    require_file(pps_file, "PPS");
    auto mapped = pipelines::imu_on_gps_time_by_pps(imu, imu_file, pps_file, s.config.attitude_gps_time_at_imu_zero);
    s.config.attitude_gps_time_at_imu_zero = mapped.origin;  // without an origin: the first PPS edge
    imu = std::move(mapped.imu);
    s.time_note = mapped.note;
  } else {
    s.time_note = "IMU t_s on the attitude time line by the GPS time origin";
  }

  std::string json;
  {
    py::gil_scoped_release release;
    const pipelines::AlignRunResult r = pipelines::run_alignment(imu, attitude, s);
    fs::create_directories(out);
    json = pipelines::alignment_json(r, s);
    io::write_file_atomically(fs::path(out) / "alignment.csv", pipelines::alignment_csv(r));
    io::write_file_atomically(fs::path(out) / "alignment.json", json);
  }
  return json;
}

}  // namespace

void register_align(py::module_& m) {
  m.def("_align", &align, py::arg("imu"), py::arg("attitude"), py::arg("out"), py::arg("config"), py::arg("position"),
        py::arg("attitude_origin"), py::arg("imu_pps"), py::arg("reference_attitude"), py::arg("duration"),
        py::arg("filter_interval"), py::arg("filter"));
}

}  // namespace ultratrack::python
