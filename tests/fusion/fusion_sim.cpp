// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion_sim.hpp"

#include <Eigen/Cholesky>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <random>

#include "fusion/ins_error_state.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_correction.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "io/units.hpp"
#include "receiver/pvt.hpp"
#include "signals/atmosphere.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::fusion::test {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;

void geodetic(const Eigen::Vector3d& r_e, double& lat, double& lon, double& h) {
  double la = 0, lo = 0;
  GeographicLib::Geocentric::WGS84().Reverse(r_e.x(), r_e.y(), r_e.z(), la, lo, h);
  lat = la * io::kRadPerDeg;
  lon = lo * io::kRadPerDeg;
}

// Receiver clock truth on the IMU grid: bias random walk (white frequency) and drift random walk.
struct ClockTruth {
  double t0 = 0.0, dt = 0.01;
  std::vector<double> b, d;
  TruthClock at(double t) const {
    const double x = std::clamp((t - t0) / dt, 0.0, static_cast<double>(b.size() - 2));
    const std::size_t i = static_cast<std::size_t>(x);
    const double f = x - i;
    return {b[i] + f * (b[i + 1] - b[i]), d[i] + f * (d[i + 1] - d[i])};
  }
};

}  // namespace

void geodetic_from_ecef(const Eigen::Vector3d& r_e, double& lat_rad, double& lon_rad, double& height_m) {
  geodetic(r_e, lat_rad, lon_rad, height_m);
}

double rms3(const std::vector<Eigen::Vector3d>& v, std::size_t from) {
  double s = 0.0;
  std::size_t n = 0;
  for (std::size_t i = from; i < v.size(); ++i, ++n) s += v[i].squaredNorm();
  return n ? std::sqrt(s / n) : 0.0;
}

double rms(const std::vector<double>& v, std::size_t from) {
  double s = 0.0;
  std::size_t n = 0;
  for (std::size_t i = from; i < v.size(); ++i, ++n) s += v[i] * v[i];
  return n ? std::sqrt(s / n) : 0.0;
}

SimulatedEpoch simulate_epoch(const ins::TruthInterpolator& truth, const Eigen::Vector3d& lever_arm_b,
                              const std::vector<signals::Ephemeris>& ephemerides,
                              const signals::KlobucharParameters& iono, const signals::GpsTime& origin, double t_true_s,
                              const TruthClock& clock, bool troposphere) {
  SimulatedEpoch out;
  out.t_true_s = t_true_s;
  out.epoch.receive_time = signals::add_seconds(origin, t_true_s + clock.bias_m / kC);
  for (const auto& eph : ephemerides) {
    // Pseudorange at true time t with receiver clock bias b; elevation returned through el.
    double az = 0.0;
    auto pseudorange = [&](double t, double b, double& el) {
      const Eigen::Vector3d r_rx = truth.antenna(t, lever_arm_b).r_e;
      double tau = 0.075;
      signals::SatelliteState sat;
      signals::GpsTime t_tx;
      for (int it = 0; it < 5; ++it) {
        t_tx = signals::add_seconds(origin, t - tau);
        sat = signals::satellite_state(eph, t_tx);
        tau = signals::geometric_range_m(sat.r_e_m, r_rx) / kC;
      }
      const Eigen::Vector3d r_sat = signals::rotate_to_receive_frame(sat.r_e_m, tau);
      const signals::LookAngles la = signals::look_angles(r_rx, r_sat);
      el = la.elevation_rad;
      az = la.azimuth_rad;
      double lat, lon, h;
      geodetic(r_rx, lat, lon, h);
      double delay = troposphere ? signals::troposphere_delay_m(lat, h, std::max(el, 5.0 * io::kRadPerDeg)) : 0.0;
      if (iono.valid) delay += kC * signals::klobuchar_delay_s(iono, lat, lon, la.azimuth_rad, el, t_tx.tow_s);
      return kC * tau + b - kC * signals::l1_ca_clock_correction_s(eph, t_tx) + delay;
    };
    double el = 0.0, el2 = 0.0;
    const double pr = pseudorange(t_true_s, clock.bias_m, el);
    const double az0 = az;
    if (el < 10.0 * io::kRadPerDeg) continue;
    const double dt = 0.05;
    const double rate = (pseudorange(t_true_s + dt, clock.bias_m + clock.drift_mps * dt, el2) -
                         pseudorange(t_true_s - dt, clock.bias_m - clock.drift_mps * dt, el2)) /
                        (2.0 * dt);
    receiver::Observation o;
    o.prn = eph.prn;
    o.pseudorange_m = pr;
    o.doppler_hz = -rate / signals::kL1Wavelength_m;
    o.cn0_dbhz = 30.0 + 20.0 * std::sin(el);  // for ordering (highest first); the tests weight uniformly
    out.epoch.observations.push_back(o);
    out.los_ned.emplace_back(std::cos(el) * std::cos(az0), std::cos(el) * std::sin(az0), -std::sin(el));
  }
  return out;
}

RunResult run_simulation(const SimConfig& cfg, fusion::Coupling coupling, fusion::FilterKind filter) {
  const bool tight = coupling == fusion::Coupling::kTight;
  const ins::TrajectorySpec spec =
      ins::profile_spec(cfg.profile, cfg.duration_s, 37.0 * io::kRadPerDeg, 127.0 * io::kRadPerDeg, 100.0);
  const ins::SimulatedRun run = ins::simulate(spec, cfg.imu_rate_hz);
  const ins::TruthInterpolator interp(run.truth);
  const ins::ImuErrorSpec imu_spec = ins::imu_preset(cfg.imu_preset);
  ins::ImuErrorModel imu(imu_spec, cfg.seed);
  std::mt19937_64 rng(cfg.seed * 7919 + 17);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto gauss3 = [&] { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)); };

  const signals::GpsTime origin{2300, 200000.0};
  const signals::NominalConstellation constellation = signals::nominal_constellation(origin);

  // Receiver clock truth (tight) with the filter's default noise densities.
  fusion::ClockNoiseModel clock_model = fusion::clock_noise_from_allan(cfg.oscillator);
  ClockTruth clock;
  clock.dt = 1.0 / cfg.imu_rate_hz;
  {
    double b = 1500.0, d = 20.0;
    const std::size_t n = run.truth.size() + 2;
    clock.b.reserve(n);
    clock.d.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      clock.b.push_back(b);
      clock.d.push_back(d);
      b += d * clock.dt + std::sqrt(clock_model.bias_psd_m2_per_s * clock.dt) * n01(rng);
      d += std::sqrt(clock_model.drift_psd_m2_per_s3 * clock.dt) * n01(rng);
    }
  }

  fusion::IntegrationOptions opt;
  opt.coupling = coupling;
  opt.filter = filter;
  opt.model = fusion::error_model_from_preset(imu_spec);
  opt.model.clock = clock_model;
  opt.height_aiding = cfg.height_aiding;
  opt.model.clock.bias_sigma_m = 30.0;
  opt.model.clock.drift_sigma_mps = 1.0;
  opt.lever_arm_b = cfg.lever_arm_b;
  opt.sigma_pos_ned_m = cfg.sigma0_pos_m;
  opt.sigma_vel_n_mps = cfg.sigma0_vel_mps;
  opt.sigma_att_rad = cfg.sigma0_att_rad;
  opt.recovery = cfg.recovery;
  opt.fix_error = cfg.fix_error;
  opt.gps_time_origin = origin;
  opt.tight.sigma_range_zenith_m = cfg.sigma_range_m;
  opt.tight.sigma_rate_zenith_mps = cfg.sigma_rate_mps;
  opt.tight.elevation_weighting = false;
  const Eigen::Vector3d clock_err0(n01(rng) * 30.0, n01(rng) * 1.0, 0.0);
  opt.initial_clock_bias_m = clock.b[0] + clock_err0.x();
  opt.initial_clock_drift_mps = clock.d[0] + clock_err0.y();

  // Initial INS state: the truth with errors drawn from the filter's initial sigmas.
  fusion::StateVector<15> e0 = fusion::StateVector<15>::Zero();
  e0.segment<3>(fusion::ix::kPos) = cfg.sigma0_pos_m.cwiseProduct(gauss3());
  e0.segment<3>(fusion::ix::kVel) = cfg.sigma0_vel_mps.cwiseProduct(gauss3());
  e0.segment<3>(fusion::ix::kAtt) = cfg.sigma0_att_rad.cwiseProduct(gauss3());
  e0.segment<3>(fusion::ix::kPos) += cfg.initial_offset_pos_m;
  e0.segment<3>(fusion::ix::kAtt) += cfg.initial_offset_att_rad;
  fusion::NominalState truth0;
  truth0.nav = run.truth[0].nav();
  const ins::NavState initial = fusion::corrected<15>(truth0, fusion::StateVector<15>(-e0)).nav;

  fusion::GnssInsIntegration integ(initial, opt);
  RunResult res;
  res.state_size = tight ? 17 : 15;

  const double imu_dt = 1.0 / cfg.imu_rate_hz;
  double next_gnss = cfg.gnss_offset_s;  // loose: true time; tight: receiver-clock time
  bool record_pending = false;
  std::vector<Eigen::Vector3d> last_los;
  std::vector<int> last_prns;
  std::size_t epochs = 0;
  auto in_outage = [&](double t) {
    return t > cfg.outage_start_s + 1e-6 && t < cfg.outage_start_s + cfg.outage_length_s - 1e-6;
  };
  auto horizontal_error = [&](std::size_t k) {
    const Eigen::Vector3d e = ins::position_error_ned(integ.output().nav, run.truth[k].nav());
    return std::hypot(e.x(), e.y());
  };
  bool outage_measured = cfg.outage_length_s <= 0.0;
  Eigen::Vector3d fix_error = Eigen::Vector3d::Zero();
  double fix_error_t_s = -1e300;

  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) {
    const double t_end = run.truth[k + 1].t_s;
    // GNSS data whose time falls in this IMU interval go in before the IMU increment.
    while (next_gnss <= t_end) {
      double t_true = next_gnss;
      TruthClock ck{};
      if (tight) {  // receiver-clock epoch -> true time
        for (int it = 0; it < 3; ++it) t_true = next_gnss - clock.at(t_true).bias_m / kC;
        ck = clock.at(t_true);
      }
      if (!in_outage(t_true)) {
        if (!outage_measured && t_true >= cfg.outage_start_s + cfg.outage_length_s - 1e-6) {
          res.outage_drift_h_m = horizontal_error(k);
          const Eigen::Vector3d s = integ.output().sigma_pos_ned_m;
          res.outage_sigma_h_m = std::hypot(s.x(), s.y());
          outage_measured = true;
        }
        const ins::EcefMotion ant = interp.antenna(t_true, cfg.lever_arm_b);
        if (!tight) {
          Eigen::Vector3d noise = cfg.sigma_pos_ned_m.cwiseProduct(gauss3());
          if (cfg.fix_error_correlation_s > 0.0) {  // Gauss-Markov from a stationary start
            if (fix_error_t_s > -1e299) {
              const double phi = std::exp(-(t_true - fix_error_t_s) / cfg.fix_error_correlation_s);
              noise = phi * fix_error + std::sqrt(1.0 - phi * phi) * noise;
            }
            fix_error = noise;
            fix_error_t_s = t_true;
          }
          if (t_true >= cfg.bias_start_s && t_true < cfg.bias_start_s + cfg.bias_length_s)
            noise += cfg.bias_offset_ned_m;
          double lat, lon, h;
          geodetic(ant.r_e, lat, lon, h);
          const Eigen::Vector3d r_noisy = ant.r_e + ins::C_en(lat, lon) * noise;
          fusion::GnssFix fix;
          fix.t_s = t_true;
          geodetic(r_noisy, fix.lat_rad, fix.lon_rad, fix.height_m);
          fix.sigma_pos_ned_m = cfg.sigma_pos_ned_m;
          fix.has_velocity = cfg.velocity;
          fix.v_n_mps = ins::C_en(lat, lon).transpose() * ant.v_e + cfg.sigma_vel_n_mps.cwiseProduct(gauss3());
          fix.sigma_vel_n_mps = cfg.sigma_vel_n_mps;
          integ.add_fix(fix);
          res.gnss_err_h_m.push_back(std::hypot(noise.x(), noise.y()));
          res.gnss_err_3d_m.push_back(noise.norm());
        } else {
          SimulatedEpoch se = simulate_epoch(interp, cfg.lever_arm_b, constellation.ephemerides,
                                             constellation.klobuchar, origin, t_true, ck);
          auto& obs = se.epoch.observations;
          if (cfg.max_satellites > 0 && t_true >= cfg.reduce_after_s &&
              static_cast<int>(obs.size()) > cfg.max_satellites) {
            std::vector<std::size_t> order(obs.size());
            for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
            std::sort(order.begin(), order.end(),
                      [&](std::size_t a, std::size_t b) { return obs[a].cn0_dbhz > obs[b].cn0_dbhz; });
            std::vector<receiver::Observation> kept;
            std::vector<Eigen::Vector3d> kept_los;
            for (int i = 0; i < cfg.max_satellites; ++i) {
              kept.push_back(obs[order[i]]);
              kept_los.push_back(se.los_ned[order[i]]);
            }
            obs = kept;
            se.los_ned = kept_los;
          }
          if (!cfg.keep_prns.empty() && t_true >= cfg.reduce_after_s) {
            std::vector<receiver::Observation> kept;
            std::vector<Eigen::Vector3d> kept_los;
            for (std::size_t i = 0; i < obs.size(); ++i) {
              if (std::find(cfg.keep_prns.begin(), cfg.keep_prns.end(), obs[i].prn) == cfg.keep_prns.end()) continue;
              kept.push_back(obs[i]);
              kept_los.push_back(se.los_ned[i]);
            }
            obs = kept;
            se.los_ned = kept_los;
          }
          last_los = se.los_ned;
          last_prns.clear();
          for (const auto& o : obs) last_prns.push_back(o.prn);
          for (auto& o : obs) {
            o.pseudorange_m += cfg.sigma_range_m * n01(rng);
            o.doppler_hz -= cfg.sigma_rate_mps * n01(rng) / signals::kL1Wavelength_m;
          }
          // GNSS-only reference: receiver/pvt on the same measurements.
          std::vector<receiver::SatelliteMeasurement> sm;
          for (const auto& o : obs) {
            receiver::SatelliteMeasurement m;
            m.prn = o.prn;
            m.pseudorange_m = o.pseudorange_m;
            m.doppler_hz = o.doppler_hz;
            m.has_doppler = true;
            m.ephemeris = constellation.ephemerides[o.prn - 1];
            sm.push_back(m);
          }
          receiver::PvtOptions po;
          po.fault_exclusion = false;
          po.sigma_zenith_m = cfg.sigma_range_m;
          const receiver::PvtSolution pvt = receiver::solve_pvt(sm, se.epoch.receive_time, constellation.klobuchar, po);
          if (pvt.valid && t_true >= cfg.reduce_after_s && (cfg.max_satellites > 0 || !cfg.keep_prns.empty()))
            ++res.pvt_fixes_reduced;
          if (pvt.valid) {
            const Eigen::Vector3d d_n = ins::C_en(pvt.lat_rad, pvt.lon_rad).transpose() * (pvt.r_e_m - ant.r_e);
            res.gnss_err_h_m.push_back(std::hypot(d_n.x(), d_n.y()));
            res.gnss_err_3d_m.push_back(d_n.norm());
          }
          integ.add_observations(se.epoch, constellation.ephemerides, constellation.klobuchar);
        }
        record_pending = true;
        ++epochs;
      }
      next_gnss += cfg.gnss_period_s;
    }
    ins::ImuIncrement ideal = run.imu[k];
    integ.add_imu(imu.apply(ideal, imu_dt));
    if (record_pending) {
      record_pending = false;
      fusion::NominalState truth;
      truth.nav = run.truth[k + 1].nav();
      truth.accel_bias_b = imu.accel_bias();
      truth.gyro_bias_b = imu.gyro_bias();
      const fusion::NominalState nom = integ.nominal();
      const Eigen::MatrixXd P = integ.covariance();
      Eigen::VectorXd e;
      if (tight) {
        const TruthClock c = clock.at(t_end);
        truth.clock_bias_m = c.bias_m;
        truth.clock_drift_mps = c.drift_mps;
        e = fusion::error_state<17>(nom, truth);
      } else {
        e = fusion::error_state<15>(nom, truth);
      }
      res.t_s.push_back(t_end);
      res.pos_err_m.push_back(e.segment<3>(0));
      res.sigma_pos_m.push_back(integ.output().sigma_pos_ned_m);
      res.los_ned.push_back(last_los);
      res.prns.push_back(last_prns);
      res.nees.push_back(e.dot(P.ldlt().solve(e)));
      const Eigen::VectorXd e9 = e.head(9);
      const Eigen::MatrixXd P9 = P.topLeftCorner(9, 9);
      res.nees_nav.push_back(e9.dot(P9.ldlt().solve(e9)));
    }
  }
  res.accepted = integ.counters().accepted;
  res.rejected = integ.counters().rejected;
  res.counters = integ.counters();
  (void)epochs;
  return res;
}

}  // namespace ultratrack::fusion::test
