// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack covariance`: the [ChoUKF] covariance analysis of tightly or ultra-tightly coupled GPS/INS (17
// states, eq. 38 noise; ultra-tight: I&Q taps or their discriminators every coherent integration, noise from
// C/N0) on a named trajectory with an EKF or a UKF; prints position 1-sigma (north, east, down) at 30 s and
// 150 s (or the given times) and optionally writes the whole history as CSV.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "commands.hpp"
#include "fusion/covariance_analysis.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::tools {
namespace {

struct CovarianceCommandOptions {
  std::string trajectory, coupling = "tight", filter = "ekf", nav_file, csv_file, iq_measurement = "iq";
  double cn0_dbhz = 45.0, integration_ms = 20.0, spacing_chips = 1.0, ukf_alpha = 1.0;
  std::vector<double> times{30.0, 150.0};
  double duration_s = 0.0;
  bool range_rate = false, absolute_phase = false;
  double lat_deg = 36.37, lon_deg = 127.36, height_m = 1000.0;
};

void run_covariance_command(const CovarianceCommandOptions& c) {
  if (c.coupling != "tight" && c.coupling != "ultra-tight")
    throw io::InputError("command line", "--coupling must be tight or ultra-tight, got '" + c.coupling + "'");
  const bool ultra = c.coupling == "ultra-tight";
  fusion::IqForm form = fusion::IqForm::Iq;
  if (c.iq_measurement == "discriminator") {
    form = fusion::IqForm::Discriminator;
  } else if (c.iq_measurement != "iq") {
    throw io::InputError("command line",
                         "--iq-measurement must be iq or discriminator, got '" + c.iq_measurement + "'");
  }
  if (!(c.integration_ms > 0.0) || !(c.spacing_chips > 0.0) || !(c.spacing_chips <= 1.0) || !(c.ukf_alpha > 0.0))
    throw io::InputError("command line",
                         "--integration-ms and --ukf-alpha must be positive, --spacing-chips in (0, 1]");
  fusion::FilterKind kind;
  if (c.filter == "ekf") {
    kind = fusion::FilterKind::Ekf;
  } else if (c.filter == "ukf") {
    kind = fusion::FilterKind::Ukf;
  } else {
    throw io::InputError("command line", "--filter must be ekf or ukf, got '" + c.filter + "'");
  }
  fusion::CovarianceAnalysisOptions o = fusion::seed001_covariance_options(c.trajectory, kind);
  if (c.absolute_phase && !(ultra && form == fusion::IqForm::Iq))
    throw io::InputError("command line", "--absolute-carrier-phase needs --coupling ultra-tight --iq-measurement iq");
  if (ultra) {
    fusion::IqSettings iq;
    iq.cn0_dbhz = c.cn0_dbhz;
    iq.integration_time_s = c.integration_ms * 1e-3;
    iq.tap_offset_chips = 0.5 * c.spacing_chips;
    iq.absolute_carrier_phase = c.absolute_phase;
    o = fusion::seed001_ultratight_options(c.trajectory, kind, form);
    o.iq = iq;
    o.update_interval_s = o.propagation_interval_s = iq.integration_time_s;  // one update per integration
  }
  o.ukf.alpha = c.ukf_alpha;
  double last = 0.0;
  for (double t : c.times) {
    if (!(t > 0.0)) throw io::InputError("command line", "--times must be positive");
    last = std::max(last, t);
  }
  o.duration_s = c.duration_s > 0.0 ? c.duration_s : last;
  o.use_range_rate = c.range_rate;
  o.lat_rad = c.lat_deg * io::kRadPerDeg;
  o.lon_rad = c.lon_deg * io::kRadPerDeg;
  o.height_m = c.height_m;
  if (!c.nav_file.empty()) o.ephemerides = signals::read_rinex_nav(c.nav_file).ephemerides;
  const fusion::CovarianceAnalysisResult r = fusion::run_covariance_analysis(o);
  const int nsat = r.samples.size() > 1 ? r.samples[1].satellites : 0;
  const std::string source = c.nav_file.empty() ? "nominal constellation" : c.nav_file;
  if (ultra) {
    const fusion::DiscriminatorNoise n = fusion::discriminator_noise(o.iq);
    fmt::print(
        "covariance: {} trajectory, ultra-tight {} ({}), {} satellites ({}), eq. 38 noise, {:.1f} dB-Hz, "
        "T {:g} ms, E-L {:g} chip, A {:.2f}{}\n",
        c.trajectory, c.filter, c.iq_measurement, nsat, source, c.cn0_dbhz, c.integration_ms, c.spacing_chips,
        fusion::iq_amplitude(o.iq),
        (c.filter == "ukf" ? fmt::format(", alpha {:g}", c.ukf_alpha) : "") +
            (c.absolute_phase ? ", absolute carrier phase" : ""));
    if (form == fusion::IqForm::Discriminator)
      fmt::print("discriminator 1-sigma per interval: range {:.3f} m, rate {:.4f} m/s\n", n.range_sigma_m,
                 n.rate_sigma_mps);
  } else {
    fmt::print("covariance: {} trajectory, tight {}, {} satellites ({}), eq. 38 noise{}\n", c.trajectory, c.filter,
               nsat, source, c.range_rate ? ", pseudorange + rate" : ", pseudorange only");
  }
  fmt::print("{:>8}  {:>10}  {:>10}  {:>10}\n", "t_s", "sigma_n_m", "sigma_e_m", "sigma_d_m");
  for (double t : c.times) {
    const auto s = r.at(t);
    fmt::print("{:8.2f}  {:10.4f}  {:10.4f}  {:10.4f}\n", s.t_s, s.sigma_pos_ned_m.x(), s.sigma_pos_ned_m.y(),
               s.sigma_pos_ned_m.z());
  }
  if (!c.csv_file.empty()) {
    std::string text = "t_s,sigma_n_m,sigma_e_m,sigma_d_m,satellites\n";
    for (const auto& s : r.samples)
      text += fmt::format("{},{},{},{},{}\n", s.t_s, s.sigma_pos_ned_m.x(), s.sigma_pos_ned_m.y(),
                          s.sigma_pos_ned_m.z(), s.satellites);
    io::write_file_atomically(c.csv_file, text);
  }
}

}  // namespace

void add_covariance_command(CLI::App& app) {
  auto o = std::make_shared<CovarianceCommandOptions>();
  auto* cmd =
      app.add_subcommand("covariance", "Seed 001 covariance analysis of tight / ultra-tight GPS/INS (EKF or UKF)");
  cmd->add_option("--trajectory", o->trajectory, "straight, circle, s or spiral")->required();
  cmd->add_option("--coupling", o->coupling, "tight (default) or ultra-tight");
  cmd->add_option("--iq-measurement", o->iq_measurement, "ultra-tight: iq (taps, default) or discriminator");
  cmd->add_option("--cn0-dbhz", o->cn0_dbhz, "ultra-tight: C/N0 of every satellite (default 45)");
  cmd->add_option("--integration-ms", o->integration_ms,
                  "ultra-tight: coherent integration = update interval (default 20)");
  cmd->add_option("--spacing-chips", o->spacing_chips, "ultra-tight: early-late spacing (default 1)");
  cmd->add_option("--ukf-alpha", o->ukf_alpha, "UKF sigma-point spread alpha (default 1)");
  cmd->add_flag("--absolute-carrier-phase", o->absolute_phase,
                "ultra-tight iq: carrier phase error from the range error (seed eq. 8b; integer ambiguity known)");
  cmd->add_option("--filter", o->filter, "ekf or ukf (default ekf)");
  cmd->add_option("--times", o->times, "report times in seconds (default 30 150)");
  cmd->add_option("--duration", o->duration_s, "seconds simulated (default: the last report time)");
  cmd->add_option("--nav", o->nav_file, "RINEX navigation file (default: the nominal 24-slot constellation)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--range-rate", o->range_rate, "also use pseudorange rates (0.1 m/s)");
  cmd->add_option("--lat-deg", o->lat_deg, "start latitude (default 36.37)");
  cmd->add_option("--lon-deg", o->lon_deg, "start longitude (default 127.36)");
  cmd->add_option("--height-m", o->height_m, "start height (default 1000)");
  cmd->add_option("--csv", o->csv_file, "write the 1-sigma history to this CSV");
  cmd->callback([o] { run_covariance_command(*o); });
}

}  // namespace ultratrack::tools
