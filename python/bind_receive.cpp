// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.receive: one recording received into a folder (pipelines/receive_file.hpp) with `ultratrack
// receive`'s settings under the command line's names (--elevation-mask-deg -> elevation_mask_deg), applied in
// the command's order (defaults, then `config`, then the single settings), so that the same settings give the
// same files. Returns the run's ReceiveSummary as a dict.
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "bindings.hpp"
#include "config/fuse_config_toml.hpp"
#include "config/receive_config_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/imu_error_model.hpp"
#include "io/why_invalid.hpp"
#include "pipelines/receive_file.hpp"
#include "receiver/nav_bit_source.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::python {

namespace {

using pipelines::Coupling;

// The GNSS/INS settings (coupling loose, tight, ultra-tight); the same checks as the command line's.
void apply_fusion_options(py::dict& o, pipelines::ReceiveOptions& s) {
  std::string filter, align, fusion_config, ut_measurement, vector_carrier;
  py::object time_origin = py::none();
  bool ut_pipelined = s.ut_pipelined;
  double ut_clock_loop_bw_hz = s.ut_clock_loop_bw_hz;
  const bool has_filter = take_option(o, "filter", filter), has_align = take_option(o, "align", align);
  const bool has_config = take_option(o, "fusion_config", fusion_config);
  const bool has_origin = take_option(o, "imu_time_origin", time_origin);
  const bool has_form = take_option(o, "ut_measurement", ut_measurement);
  const bool has_pipelined = take_option(o, "ut_pipelined", ut_pipelined);
  const bool has_clock_loop = take_option(o, "ut_clock_loop_bw_hz", ut_clock_loop_bw_hz);
  if (take_option(o, "vector_carrier", vector_carrier)) {
    if (s.coupling != Coupling::kVector) throw io::InputError("python", "vector_carrier needs coupling='vector'");
    s.vector_carrier =
        enum_from_name("vector_carrier", vector_carrier,
                       {fusion::VectorCarrier::kAidedPll, fusion::VectorCarrier::kFll, fusion::VectorCarrier::kPll},
                       [](fusion::VectorCarrier c) { return fusion::to_string(c); });
  }
  if (!pipelines::uses_imu(s.coupling)) {
    if (has_filter || has_align || has_config || has_origin)
      throw io::InputError("python",
                           "imu, filter, align, fusion_config and imu_time_origin need coupling "
                           "'loose', 'tight' or 'ultra-tight'");
    if (has_form || has_pipelined || has_clock_loop)
      throw io::InputError("python",
                           "ut_measurement, ut_pipelined and ut_clock_loop_bw_hz need coupling 'ultra-tight'");
    return;
  }
  if ((has_form || has_pipelined || has_clock_loop) && s.coupling != Coupling::kUltraTight)
    throw io::InputError("python", "ut_measurement, ut_pipelined and ut_clock_loop_bw_hz need coupling 'ultra-tight'");
  s.ut_pipelined = ut_pipelined;
  if (!(ut_clock_loop_bw_hz >= 0.0 && ut_clock_loop_bw_hz <= 12.5))
    throw io::InputError("python", "ut_clock_loop_bw_hz must be 0 (off) or in (0, 12.5] Hz");
  s.ut_clock_loop_bw_hz = ut_clock_loop_bw_hz;
  if (has_form)
    s.ut_form = enum_from_name(
        "ut_measurement", ut_measurement, {fusion::UltraTightForm::Iq, fusion::UltraTightForm::Discriminator},
        [](fusion::UltraTightForm f) { return f == fusion::UltraTightForm::Iq ? "iq" : "discriminator"; });
  if (has_filter)
    s.filter = enum_from_name("filter", filter, {fusion::FilterKind::Ekf, fusion::FilterKind::Ukf},
                              [](fusion::FilterKind f) { return f == fusion::FilterKind::Ekf ? "ekf" : "ukf"; });
  if (has_align)
    s.align = enum_from_name("align", align,
                             {pipelines::AlignMode::Static, pipelines::AlignMode::Motion, pipelines::AlignMode::Config},
                             [](pipelines::AlignMode a) { return pipelines::to_string(a); });
  if (has_config) s.navigation = config::read_fuse_config(fusion_config);
  (void)ins::imu_preset(s.navigation.imu_preset);  // an unknown preset fails here, before any output
  if (s.align == pipelines::AlignMode::Config && !s.navigation.attitude_deg)
    throw io::InputError(has_config ? fusion_config : "python",
                         "align='config' needs [initial] attitude_deg in fusion_config");
  if (time_origin.is_none() || (py::isinstance<py::str>(time_origin) && time_origin.cast<std::string>() == "sample0")) {
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::Sample0;
  } else if (py::isinstance<py::str>(time_origin) && time_origin.cast<std::string>() == "tow") {
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::WeekStart;
  } else {
    if (py::isinstance<py::str>(time_origin))
      throw io::InputError("python", "imu_time_origin must be 'sample0', 'tow' or a GPS time of week in seconds");
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::Tow;
    s.imu_time_origin.tow_s = time_origin.cast<double>();
    if (!(s.imu_time_origin.tow_s >= 0.0 && s.imu_time_origin.tow_s < 604800.0))
      throw io::InputError("python", "imu_time_origin: a GPS time of week lies in [0, 604800) s");
  }
}

py::dict summary_dict(const pipelines::ReceiveFileResult& result, const std::string& out) {
  const pipelines::ReceiveSummary& s = result.summary;
  py::dict d;
  d["out"] = out;
  d["coupling"] = pipelines::to_string(s.coupling);
  d["processed_s"] = s.processed_s;
  d["wall_s"] = result.wall_s;
  d["interrupted"] = s.interrupted;
  d["threads"] = s.threads;
  d["satellites_found"] = s.satellites_found;
  d["satellites_tracked"] = s.satellites_tracked;
  d["satellites_used"] = s.satellites_used;
  d["fixes"] = s.fixes;
  d["ephemerides_decoded"] = s.ephemerides_decoded;
  d["ttff_s"] = s.ttff_s >= 0.0 ? py::object(py::float_(s.ttff_s)) : py::object(py::none());
  if (s.fixes > 0) {
    d["mean_lat_deg"] = s.mean_lat_deg;
    d["mean_lon_deg"] = s.mean_lon_deg;
    d["mean_height_m"] = s.mean_height_m;
  }
  if (s.coupling == Coupling::kVector) {
    d["vector_epochs"] = s.vector_epochs;
    d["vector_channel_epochs"] = s.vector_channel_epochs;
    d["coasting_channel_epochs"] = s.coasting_channel_epochs;
    d["vector_filter_starts"] = s.vector_filter_starts;
    d["vector_filter_resets"] = s.vector_filter_resets;
  }
  if (pipelines::uses_imu(s.coupling)) {
    d["navigation_started"] = s.navigation_started;
    d["navigation_not_started"] = s.navigation_not_started;
    d["navigation_rows"] = s.navigation_rows;
  }
  if (s.coupling == Coupling::kUltraTight) {
    d["handed_over"] = s.handed_over;
    d["ultratight_channel_epochs"] = s.ultratight_channel_epochs;
  }
  d["report"] = s.report;
  return d;
}

py::dict receive(const std::string& input, const std::string& format, double fs_hz, double if_hz,
                 const std::string& coupling, const std::string& imu, const std::string& nav, const std::string& out,
                 int fallback_week, py::dict options) {
  pipelines::ReceiveFileJob job;
  job.input = input;
  job.out = out;
  const signals::SampleFormat sample_format = sample_format_from_name(format);
  job.format = sample_format;
  receiver::SampleSourceOptions& source = job.source;
  std::string coding, order;
  if (take_option(options, "two_bit_coding", coding)) {
    const auto c = signals::parse_two_bit_coding(coding);
    if (!c)
      throw io::InputError("python", "two_bit_coding: unknown coding '" + coding + "' (" +
                                         std::string(signals::two_bit_coding_names()) + ")");
    source.two_bit.coding = *c;
  }
  if (take_option(options, "two_bit_order", order)) {
    const auto b = signals::parse_bit_order(order);
    if (!b)
      throw io::InputError("python", "two_bit_order: unknown bit order '" + order + "' (" +
                                         std::string(signals::bit_order_names()) + ")");
    source.two_bit.order = *b;
  }
  source.fs_hz = fs_hz;
  source.if_hz = if_hz;
  take_option(options, "iq_swap", source.iq_swap);
  take_option(options, "q_negate", source.q_negate);
  double skip_s = 0.0;
  take_option(options, "skip", skip_s);
  if (skip_s < 0.0) throw io::InputError("python", "skip: must not be negative");
  source.start_sample = std::llround(skip_s * fs_hz);

  receiver::ReceiverOptions& r = job.options.receiver;
  r.fs_hz = fs_hz;
  std::string config;
  if (take_option(options, "config", config)) config::apply_receive_config(config, r);
  double mask_deg = 0.0;
  if (take_option(options, "elevation_mask_deg", mask_deg))
    r.pvt.elevation_mask_rad = mask_deg * M_PI / 180.0;  // as the command line, to the bit
  take_option(options, "troposphere", r.pvt.troposphere);
  take_option(options, "ionosphere", r.pvt.ionosphere);
  take_option(options, "channels", r.channels);
  take_option(options, "threads", r.threads);
  std::string nav_bits;
  if (take_option(options, "nav_bits", nav_bits))
    r.nav_bits = receiver::parse_nav_bit_source("python: nav_bits", nav_bits);
  take_option(options, "prn", r.prns);
  if (!nav.empty()) job.navigation = signals::read_rinex_nav(nav);
  if (take_option(options, "reference_week", r.reference_week)) r.reference_week_is_signal_week = true;
  pipelines::date_recording(r, job.navigation, fallback_week);
  take_option(options, "duration", job.duration_s);
  if (job.duration_s < 0.0) throw io::InputError("python", "duration: must not be negative");
  if (const std::string why = io::why_invalid(r); !why.empty())
    throw io::InputError(config.empty() ? "python" : config, why);

  const auto c = pipelines::coupling_from_string(coupling);
  if (!c)
    throw io::InputError("python",
                         "coupling must be scalar, vector, loose, tight or ultra-tight, got '" + coupling + "'");
  job.options.coupling = *c;
  if (!imu.empty() && !pipelines::uses_imu(*c))
    throw io::InputError("python", "imu needs coupling 'loose', 'tight' or 'ultra-tight'");
  apply_fusion_options(options, job.options);
  reject_unknown_options(options, "receive");
  if (std::string why; !job.options.IsValid(&why)) throw io::InputError("python", why);
  if (pipelines::uses_imu(*c)) {
    if (imu.empty()) throw io::InputError("python", "coupling '" + coupling + "' needs imu=FILE");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(imu, ec)) throw io::InputError(imu, "IMU file not found");
    job.imu = ins::read_imu_csv(imu);
    if (job.imu.size() < 2) throw io::InputError(imu, "the IMU file needs at least two rows");
    job.options.imu_name = imu;
  }

  PythonInterrupt interrupt;
  pipelines::ReceiveFileResult result;
  {
    py::gil_scoped_release release;
    result = pipelines::receive_file(std::move(job), interrupt.token(),
                                     [&](const pipelines::ReceiveProgressEvent&) { interrupt.poll(); });
  }
  interrupt.rethrow();
  return summary_dict(result, out);
}

}  // namespace

void register_receive(py::module_& m) {
  m.def("_receive", &receive, py::arg("input"), py::arg("format"), py::arg("fs"), py::arg("if_hz"), py::arg("coupling"),
        py::arg("imu"), py::arg("nav"), py::arg("out"), py::arg("fallback_week"), py::arg("options"));
}

}  // namespace ultratrack::python
