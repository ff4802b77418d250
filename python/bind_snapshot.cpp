// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.snapshot: a position from a short recording with broadcast ephemerides and an approximate time
// (pipelines/snapshot_file.hpp) with `ultratrack snapshot`'s settings under its names, into out/snapshot.json and
// out/solution.csv as the command writes them. Returns whether there is a fix; the Python wrapper reads
// snapshot.json into the summary dict. A run without a fix is no error here (the command exits 3): the dict says
// why (valid, failure).
#include <pybind11/stl.h>

#include <GeographicLib/Geocentric.hpp>
#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include "bindings.hpp"
#include "io/why_invalid.hpp"
#include "pipelines/snapshot_file.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::python {

namespace {

bool snapshot(const std::string& input, const std::string& format, double fs_hz, double if_hz, const std::string& nav,
              int week, double tow_s, const std::string& out, double time_sigma_s,
              const std::optional<std::vector<double>>& approx_llh, double ms, double skip_s,
              const std::vector<int>& prns, double doppler_max_hz, double pfa, double spacing_chips, bool iq_swap,
              bool q_negate) {
  const auto started = std::chrono::steady_clock::now();
  pipelines::SnapshotFileJob job;
  job.input = input;
  const signals::SampleFormat sample_format = sample_format_from_name(format);
  job.format = sample_format;
  job.source.fs_hz = fs_hz;
  job.source.if_hz = if_hz;
  job.source.iq_swap = iq_swap;
  job.source.q_negate = q_negate;
  if (!(skip_s >= 0.0)) throw io::InputError("python", "skip must be >= 0");
  job.source.start_sample = std::llround(skip_s * fs_hz);
  if (week < 0 || !(tow_s >= 0.0 && tow_s < 604800.0))
    throw io::InputError("python", "time: week must be >= 0 and TOW in [0, 604800)");
  job.approximate_time = signals::GpsTime{week, tow_s};
  job.navigation.time_sigma_s = time_sigma_s;
  if (approx_llh) {
    const std::vector<double>& v = *approx_llh;
    if (v.size() != 3 || !(std::fabs(v[0]) <= 90.0) || !(std::fabs(v[1]) <= 360.0))
      throw io::InputError("python", "approx_llh: expected (LAT, LON, H) in degrees and metres");
    double x = 0, y = 0, z = 0;
    GeographicLib::Geocentric::WGS84().Forward(v[0], v[1], v[2], x, y, z);  // as the command line, to the bit
    job.approximate_position_e_m = Eigen::Vector3d(x, y, z);
  }
  job.snapshot_ms = ms;
  if (!(job.snapshot_ms >= 2.0 && job.snapshot_ms <= 10000.0))
    throw io::InputError("python", "ms must be in [2, 10000]");
  job.search.fs_hz = fs_hz;
  job.search.doppler_max_hz = doppler_max_hz;
  job.search.pfa = pfa;
  job.search.spacing_chips = spacing_chips;
  for (const int prn : prns)
    if (prn < 1 || prn > 32) throw io::InputError("python", "prn: " + std::to_string(prn) + " is not within 1-32");
  job.prns = prns;
  std::string why;
  if (!job.search.IsValid(&why)) throw io::InputError("python", why);
  if (why = io::why_invalid(job.navigation); !why.empty()) throw io::InputError("python", why);
  job.nav = signals::read_rinex_nav(nav);
  if (job.nav.ephemerides.empty()) throw io::InputError(nav, "holds no GPS ephemeris");

  pipelines::SnapshotFileResult result;
  {
    py::gil_scoped_release release;
    result = pipelines::snapshot_file(job);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    pipelines::write_snapshot_outputs(out, job, result, format, wall_s);
  }
  return result.solution.valid;
}

}  // namespace

void register_snapshot(py::module_& m) {
  m.def("_snapshot", &snapshot, py::arg("input"), py::arg("format"), py::arg("fs"), py::arg("if_hz"), py::arg("nav"),
        py::arg("week"), py::arg("tow_s"), py::arg("out"), py::arg("time_sigma_s"), py::arg("approx_llh"),
        py::arg("ms"), py::arg("skip"), py::arg("prn"), py::arg("doppler_max"), py::arg("pfa"),
        py::arg("spacing_chips"), py::arg("iq_swap"), py::arg("q_negate"));
}

}  // namespace ultratrack::python
