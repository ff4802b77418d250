// SPDX-License-Identifier: GPL-3.0-or-later
#include "receive_fusion_options.hpp"

#include <filesystem>

#include "cli_parse.hpp"
#include "config/fuse_config_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/odometer_csv.hpp"
#include "io/input_error.hpp"
#include "pipelines/alignment_run.hpp"
#include "pipelines/pps_time_sync.hpp"

namespace ultratrack::tools {
namespace {

using pipelines::Coupling;
constexpr double kWeek_s = 604800.0;

}  // namespace

void add_receive_fusion_options(CLI::App* cmd, ReceiveFusionArgs& a) {
  cmd->add_option("--imu", a.imu, "IMU CSV (t_s,dtheta_x_rad,...,dv_z_mps) for GNSS/INS integration (--coupling)");
  cmd->add_option("--coupling", a.coupling,
                  "scalar (default: per-channel loops), vector (one vector filter closes the code loops), or "
                  "GNSS/INS integration with --imu: loose (PVT fixes), tight (pseudoranges and rates) or "
                  "ultra-tight (the INS-predicted replica drives the channels, the filter updates from correlations)");
  cmd->add_option("--filter", a.filter, "with --coupling: ekf (default) or ukf");
  cmd->add_option("--align", a.align,
                  "with --coupling: static, motion (default), config or file:ALIGNMENT.json (`ultratrack align`)");
  cmd->add_option("--fusion-config", a.config,
                  "with --coupling: TOML with `fuse`'s keys ([imu] [initial] [alignment] [gnss] [filter] [output])");
  cmd->add_option("--odometer", a.odometer,
                  "with --imu: odometer CSV (t_s,pulses,distance_m; t_s on the IMU's time line) as VMS "
                  "speed and non-holonomic updates ([odometer] keys in --fusion-config), as `fuse --odometer`; "
                  "bridges signal blockages");
  cmd->add_option("--imu-time-origin", a.time_origin,
                  "IMU t_s = 0 at: sample0 (default: the input's first sample, as simulate writes), tow (t_s is "
                  "the GPS time of week) or a GPS time of week in seconds");
  cmd->add_option("--imu-pps", a.imu_pps,
                  "PPS CSV (local_s,gps_week,gps_tow_s): IMU stamps are a free-running local clock, mapped to GPS "
                  "time through the PPS record (instead of --imu-time-origin)");
  cmd->add_option("--ut-measurement", a.ut_measurement,
                  "with --coupling ultra-tight: iq (default: the E/P/L I&Q, [ChoUKF] eqs. 11-17) or discriminator");
  cmd->add_flag("--ut-serial", a.ut_serial,
                "with --coupling ultra-tight: run the loop between blocks, its commands at once: the default (kept "
                "for older command lines)");
  a.ut_pipelined_option = cmd->add_flag(
      "--ut-pipelined", a.ut_pipelined,
      "with --coupling ultra-tight: run the loop beside the correlation of the next block, its commands reaching the "
      "channels one 20 ms loop period later: ~17 % faster with 2 threads, but the common clock loop's extra period "
      "of delay makes it ring with the channels' PLLs on weak signals (either way the same output for any "
      "--threads)");
  a.ut_clock_loop_bw_option = cmd->add_option(
      "--ut-clock-loop-bw", a.ut_clock_loop_bw_hz,
      "with --coupling ultra-tight: noise bandwidth (Hz, default 5; 0: off) of the common clock loop, which tracks "
      "the receiver oscillator's phase on all channels' prompts at once and steers every channel's carrier with it, "
      "so that each PLL narrows to its thermal optimum (a TCXO otherwise holds them at 5 Hz, 20 ms)");
  cmd->add_option("--vector-carrier", a.vector_carrier,
                  "with --coupling vector: aided-pll (default: each channel's PLL, aided), fll (the filter "
                  "commands the carrier NCOs: vector FLL) or pll (the filter commands the carrier NCOs' frequency "
                  "and phase from per-channel carrier states its Costas discriminators update: vector PLL)");
  a.nis_window_option =
      cmd->add_option("--nis-window", a.nis_window,
                      "with --coupling vector or ultra-tight: updates (20 ms each) in each channel's windowed NIS test "
                      "(default 50); a channel whose window is far outside its chi-square band is released to scalar "
                      "tracking; all channels' windows pooled far outside theirs re-open the filter's covariance");
  a.nis_probability_option =
      cmd->add_option("--nis-probability", a.nis_probability,
                      "with --coupling vector or ultra-tight: false-alarm probability of one full NIS window of a "
                      "consistent filter (default 1e-6), in (0, 1)");
}

void apply_receive_coupling_args(const ReceiveFusionArgs& a, pipelines::ReceiveOptions& s) {
  const bool pipelined_given = a.ut_pipelined_option && a.ut_pipelined_option->count() > 0;
  const bool clock_loop_given = a.ut_clock_loop_bw_option && a.ut_clock_loop_bw_option->count() > 0;
  const auto coupling = pipelines::coupling_from_string(a.coupling);
  if (!coupling)
    throw io::InputError("command line",
                         "--coupling must be scalar, vector, loose, tight or ultra-tight, got '" + a.coupling + "'");
  s.coupling = *coupling;
  const bool window_given = a.nis_window_option && a.nis_window_option->count() > 0;
  const bool probability_given = a.nis_probability_option && a.nis_probability_option->count() > 0;
  if ((window_given || probability_given) && s.coupling != Coupling::kVector && s.coupling != Coupling::kUltraTight)
    throw io::InputError("command line", "--nis-window and --nis-probability need --coupling vector or ultra-tight");
  if (window_given) s.nis_release.window = a.nis_window;
  if (probability_given) s.nis_release.probability = a.nis_probability;
  if (std::string why; !s.nis_release.IsValid(&why))
    throw io::InputError("command line", "--nis-window / --nis-probability: " + why);
  if (!a.vector_carrier.empty()) {
    if (s.coupling != Coupling::kVector)
      throw io::InputError("command line", "--vector-carrier needs --coupling vector");
    const auto carrier = fusion::vector_carrier_from_string(a.vector_carrier);
    if (!carrier)
      throw io::InputError("command line",
                           "--vector-carrier must be aided-pll, fll or pll, got '" + a.vector_carrier + "'");
    s.vector_carrier = *carrier;
  }
  if (!pipelines::uses_imu(s.coupling)) {
    if (!a.imu.empty() || !a.filter.empty() || !a.align.empty() || !a.config.empty() || !a.time_origin.empty() ||
        !a.imu_pps.empty())
      throw io::InputError("command line",
                           "--imu, --filter, --align, --fusion-config, --imu-time-origin and "
                           "--imu-pps need --coupling loose, tight or ultra-tight");
    if (!a.ut_measurement.empty())
      throw io::InputError("command line", "--ut-measurement needs --coupling ultra-tight");
    if (!a.odometer.empty())
      throw io::InputError("command line", "--odometer needs --coupling loose, tight or ultra-tight and --imu");
    if (a.ut_serial) throw io::InputError("command line", "--ut-serial needs --coupling ultra-tight");
    if (pipelined_given) throw io::InputError("command line", "--ut-pipelined needs --coupling ultra-tight");
    if (clock_loop_given) throw io::InputError("command line", "--ut-clock-loop-bw needs --coupling ultra-tight");
    return;
  }
  if (!a.ut_measurement.empty() && s.coupling != Coupling::kUltraTight)
    throw io::InputError("command line", "--ut-measurement needs --coupling ultra-tight");
  if (a.ut_serial && s.coupling != Coupling::kUltraTight)
    throw io::InputError("command line", "--ut-serial needs --coupling ultra-tight");
  if (pipelined_given && s.coupling != Coupling::kUltraTight)
    throw io::InputError("command line", "--ut-pipelined needs --coupling ultra-tight");
  if (a.ut_serial && pipelined_given && a.ut_pipelined)
    throw io::InputError("command line", "--ut-serial and --ut-pipelined exclude each other");
  s.ut_pipelined = a.ut_pipelined && !a.ut_serial;
  if (clock_loop_given && s.coupling != Coupling::kUltraTight)
    throw io::InputError("command line", "--ut-clock-loop-bw needs --coupling ultra-tight");
  if (!(a.ut_clock_loop_bw_hz >= 0.0 && a.ut_clock_loop_bw_hz <= 12.5))
    throw io::InputError("command line", "--ut-clock-loop-bw must be 0 (off) or in (0, 12.5] Hz, got " +
                                             std::to_string(a.ut_clock_loop_bw_hz));
  s.ut_clock_loop_bw_hz = a.ut_clock_loop_bw_hz;
  if (a.ut_measurement.empty() || a.ut_measurement == "iq") {
    s.ut_form = fusion::UltraTightForm::Iq;
  } else if (a.ut_measurement == "discriminator") {
    s.ut_form = fusion::UltraTightForm::Discriminator;
  } else {
    throw io::InputError("command line",
                         "--ut-measurement must be iq or discriminator, got '" + a.ut_measurement + "'");
  }
  if (a.imu.empty()) throw io::InputError("command line", "--coupling " + a.coupling + " needs --imu FILE");
  s.imu_name = a.imu;
  const std::string filter = a.filter.empty() ? "ekf" : a.filter;
  if (filter == "ekf") {
    s.filter = fusion::FilterKind::Ekf;
  } else if (filter == "ukf") {
    s.filter = fusion::FilterKind::Ukf;
  } else {
    throw io::InputError("command line", "--filter must be ekf or ukf, got '" + filter + "'");
  }
  const std::string align = a.align.empty() ? "motion" : a.align;
  const bool from_file = align.starts_with("file:");  // `ultratrack align`'s result: a configured attitude
  const auto mode = from_file ? std::optional(pipelines::AlignMode::Config) : pipelines::align_mode_from_string(align);
  if (!mode || *mode == pipelines::AlignMode::Attitude)  // attitude alignment is `fuse`'s
    throw io::InputError("command line",
                         "--align must be static, motion, config or file:ALIGNMENT.json, got '" + align + "'");
  s.align = *mode;
  if (!a.config.empty()) s.navigation = config::read_fuse_config(a.config);
  if (from_file) pipelines::apply_alignment_file(s.navigation, align.substr(5));
  (void)ins::imu_preset(s.navigation.imu_preset);  // an unknown preset fails here, before any output
  if (s.align == pipelines::AlignMode::Config && !s.navigation.attitude_deg)
    throw io::InputError(a.config.empty() ? "command line" : a.config,
                         "--align config needs [initial] attitude_deg in --fusion-config");
  if (!a.odometer.empty()) {
    s.odometer = ins::read_odometer_csv(a.odometer, {s.navigation.odometer_rate_hz}).samples;
    s.odometer_name = a.odometer;
    if (std::string why; !s.navigation.odometer.IsValid(&why))
      throw io::InputError(a.config.empty() ? "command line" : a.config, why);
  }
  if (!a.imu_pps.empty() && !a.time_origin.empty())
    throw io::InputError("command line",
                         "--imu-pps and --imu-time-origin exclude each other (the PPS record sets "
                         "the IMU's time origin)");
  if (a.time_origin.empty() || a.time_origin == "sample0") {
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::Sample0;
  } else if (a.time_origin == "tow") {
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::WeekStart;
  } else {
    s.imu_time_origin.kind = pipelines::ImuTimeOrigin::Kind::Tow;
    s.imu_time_origin.tow_s = parse_double_option("--imu-time-origin", a.time_origin);
    if (!(s.imu_time_origin.tow_s >= 0.0 && s.imu_time_origin.tow_s < kWeek_s))
      throw io::InputError("command line", "--imu-time-origin: a GPS time of week lies in [0, 604800) s");
  }
}

std::vector<ins::ImuIncrement> read_receive_imu(const std::string& file, const ins::ImuCsvOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw io::InputError(file, "IMU file not found");
  auto imu = ins::read_imu_csv(file, options);
  if (imu.size() < 2) throw io::InputError(file, "the IMU file needs at least two rows");
  return imu;
}

void put_receive_imu_on_pps(const ReceiveFusionArgs& a, std::vector<ins::ImuIncrement>& imu,
                            pipelines::ReceiveOptions& s) {
  if (a.imu_pps.empty()) return;
  auto mapped = pipelines::imu_on_gps_time_by_pps(imu, a.imu, a.imu_pps);
  imu = std::move(mapped.imu);
  s.imu_time_origin = {pipelines::ImuTimeOrigin::Kind::Tow, mapped.origin.tow_s};
}

}  // namespace ultratrack::tools
