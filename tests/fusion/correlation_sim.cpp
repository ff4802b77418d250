// SPDX-License-Identifier: GPL-3.0-or-later
#include "correlation_sim.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "fusion_sim.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_correction.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"
#include "signals/gps_constants.hpp"
#include "signals/nominal_constellation.hpp"

namespace ultratrack::fusion::test {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;
constexpr double kLambda = signals::kL1Wavelength_m;
constexpr double kChip = kC / signals::kCaChipRate_hz;
constexpr int kSub = 20;

double tri(double x) { return std::abs(x) < 1.0 ? 1.0 - std::abs(x) : 0.0; }

}  // namespace

IqTaps ideal_correlation(const std::vector<double>& code, const std::vector<double>& phase, double A, double d) {
  IqTaps t;
  const double o[3] = {d, 0.0, -d};
  const double n = static_cast<double>(code.size());
  for (std::size_t m = 0; m < code.size(); ++m)
    for (int k = 0; k < 3; ++k) {
      const double r = tri(code[m] - o[k]) * A / n;
      t.i[k] += r * std::cos(phase[m]);
      t.q[k] += r * std::sin(phase[m]);
    }
  return t;
}

CorrelationRunResult run_correlation_simulation(const CorrelationSimConfig& cfg) {
  const ins::TrajectorySpec spec =
      ins::profile_spec(cfg.profile, cfg.duration_s + 1.0, 37.0 * io::kRadPerDeg, 127.0 * io::kRadPerDeg, 100.0);
  const ins::SimulatedRun run = ins::simulate(spec, cfg.imu_rate_hz);
  const ins::TruthInterpolator interp(run.truth);
  const ins::ImuErrorSpec imu_spec = ins::imu_preset(cfg.imu_preset);
  ins::ImuErrorModel imu(imu_spec, cfg.seed);
  std::mt19937_64 rng(cfg.seed * 7919 + 17);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto gauss3 = [&] { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)); };

  const signals::GpsTime origin{2300, 200000.0};
  const signals::NominalConstellation constellation = signals::nominal_constellation(origin);
  const signals::KlobucharParameters no_iono{};

  // Receiver clock truth on the IMU grid (the filter's default noise densities).
  ClockNoiseModel clock_model;
  clock_model.bias_psd_m2_per_s = cfg.clock_bias_psd_m2_per_s;
  clock_model.drift_psd_m2_per_s3 = cfg.clock_drift_psd_m2_per_s3;
  const double imu_dt = 1.0 / cfg.imu_rate_hz;
  std::vector<double> cb, cd;
  {
    double b = 1500.0, d = 20.0;
    for (std::size_t i = 0; i < run.truth.size() + 2; ++i) {
      cb.push_back(b);
      cd.push_back(d);
      b += d * imu_dt + std::sqrt(clock_model.bias_psd_m2_per_s * imu_dt) * n01(rng);
      d += std::sqrt(clock_model.drift_psd_m2_per_s3 * imu_dt) * n01(rng);
    }
  }
  auto clock_at = [&](double t) {
    const double x = std::clamp(t / imu_dt, 0.0, static_cast<double>(cb.size() - 2));
    const std::size_t i = static_cast<std::size_t>(x);
    const double f = x - i;
    return TruthClock{cb[i] + f * (cb[i + 1] - cb[i]), cd[i] + f * (cd[i + 1] - cd[i])};
  };

  // The satellites: highest elevation at the start.
  std::vector<signals::Ephemeris> eph;
  {
    SimulatedEpoch e0 =
        simulate_epoch(interp, cfg.lever_arm_b, constellation.ephemerides, no_iono, origin, 0.0, clock_at(0.0));
    auto& obs = e0.epoch.observations;
    std::sort(obs.begin(), obs.end(), [](const auto& a, const auto& b) { return a.cn0_dbhz > b.cn0_dbhz; });
    for (std::size_t i = 0; i < obs.size() && static_cast<int>(i) < cfg.max_satellites; ++i)
      eph.push_back(constellation.ephemerides[obs[i].prn - 1]);
  }

  UltraTightOptions opt;
  opt.filter = cfg.filter;
  opt.form = cfg.form;
  opt.model = error_model_from_preset(imu_spec);
  opt.model.clock.bias_psd_m2_per_s = cfg.clock_bias_psd_m2_per_s;
  opt.model.clock.drift_psd_m2_per_s3 = cfg.clock_drift_psd_m2_per_s3;
  opt.model.clock.bias_sigma_m = cfg.sigma0_clock_bias_m;
  opt.model.clock.drift_sigma_mps = cfg.sigma0_clock_drift_mps;
  opt.lever_arm_b = cfg.lever_arm_b;
  opt.tight.troposphere = cfg.troposphere;
  opt.sigma_pos_ned_m = cfg.sigma0_pos_m;
  opt.sigma_vel_n_mps = cfg.sigma0_vel_mps;
  opt.sigma_att_rad = cfg.sigma0_att_rad;
  opt.gps_time_origin = origin;
  opt.initial_clock_bias_m = cb[0] + cfg.sigma0_clock_bias_m * n01(rng);
  opt.initial_clock_drift_mps = cd[0] + cfg.sigma0_clock_drift_mps * n01(rng);
  StateVector<15> e0 = StateVector<15>::Zero();
  e0.segment<3>(ix::kPos) = cfg.sigma0_pos_m.cwiseProduct(gauss3());
  e0.segment<3>(ix::kVel) = cfg.sigma0_vel_mps.cwiseProduct(gauss3());
  e0.segment<3>(ix::kAtt) = cfg.sigma0_att_rad.cwiseProduct(gauss3());
  NominalState truth0;
  truth0.nav = run.truth[0].nav();
  const ins::NavState initial = corrected<15>(truth0, StateVector<15>(-e0)).nav;
  UltraTightIntegration integ(initial, eph, opt);

  // Tap noise: unit variance, E/P/L correlated by the triangle at the tap spacing.
  const double d = opt.tap_offset_chips;
  Eigen::Matrix3d C;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) C(j, k) = tri((j - k) * d);
  const Eigen::Matrix3d L = C.llt().matrixL();

  CorrelationRunResult res;
  res.satellites = static_cast<int>(eph.size());
  const double T = cfg.integration_time_s;
  const int steps = static_cast<int>(std::lround(T * cfg.imu_rate_hz));
  const double A = std::sqrt(2.0 * std::pow(10.0, 0.1 * cfg.cn0_dbhz) * T);
  const std::size_t n_steps = static_cast<std::size_t>(std::lround(cfg.duration_s * cfg.imu_rate_hz));
  double cpu = 0.0;
  auto timed = [&](auto&& f) {
    const auto a = std::chrono::steady_clock::now();
    f();
    cpu += std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
  };
  std::vector<ReplicaCommand> replicas;
  std::vector<ChannelCorrelation> corr;
  std::vector<double> code(kSub), phase(kSub);
  struct Pll {
    double phase_rad = 0.0;  // carrier phase error (signal minus replica, as phase[]) at the period's start
    double integrator_hz = 0.0, correction_hz = 0.0;
  };
  std::map<int, Pll> plls;
  const double wn = cfg.pll_bw_hz / 0.53;  // 2nd order, zeta = 0.707: Bn = 0.53 wn
  for (std::size_t k = 0; k <= n_steps; ++k) {
    if (k % steps == 0) {
      if (k > 0) {
        const double t1 = run.truth[k].t_s;
        const double t0 = replicas.empty() ? t1 - T : replicas.front().t_start_s;
        const double tm = 0.5 * (t0 + t1);
        const bool blocked = tm >= cfg.blockage_start_s && tm < cfg.blockage_start_s + cfg.blockage_length_s;
        const SimulatedEpoch s0 =
            simulate_epoch(interp, cfg.lever_arm_b, eph, no_iono, origin, t0, clock_at(t0), cfg.troposphere);
        const SimulatedEpoch sm =
            simulate_epoch(interp, cfg.lever_arm_b, eph, no_iono, origin, tm, clock_at(tm), cfg.troposphere);
        const SimulatedEpoch s1 =
            simulate_epoch(interp, cfg.lever_arm_b, eph, no_iono, origin, t1, clock_at(t1), cfg.troposphere);
        corr.clear();
        double max_code = 0.0, max_freq = 0.0;
        for (const ReplicaCommand& r : replicas) {
          auto find = [&](const SimulatedEpoch& s) -> const receiver::Observation* {
            for (const auto& o : s.epoch.observations)
              if (o.prn == r.prn) return &o;
            return nullptr;
          };
          const receiver::Observation *a = find(s0), *b = find(sm), *c = find(s1);
          if (!a || !b || !c) continue;
          // Quadratic through the true pseudoranges at 0, T/2, T.
          const double p0 = a->pseudorange_m, pm = b->pseudorange_m, p1 = c->pseudorange_m;
          const double c1 = (4.0 * pm - 3.0 * p0 - p1) / T, c2 = 2.0 * (p1 - 2.0 * pm + p0) / (T * T);
          Pll& pll = plls[r.prn];
          // The replica's rate: the command's, less the PLL's correction (a higher carrier frequency is a lower
          // pseudorange rate).
          const double rep_rate = r.range_rate_mps - (cfg.pll_bw_hz > 0.0 ? kLambda * pll.correction_hz : 0.0);
          for (int m = 0; m < kSub; ++m) {
            const double s = (m + 0.5) * T / kSub;
            const double sig = p0 + c1 * s + c2 * s * s;
            const double rep = r.pseudorange_m + rep_rate * s;
            code[m] = (rep - sig) / kChip;
            phase[m] = 2.0 * M_PI * ((rep - r.pseudorange_m) - (sig - p0)) / kLambda;
            if (cfg.pll_bw_hz > 0.0) phase[m] += pll.phase_rad;
          }
          if (cfg.start_phase_sigma_rad > 0.0) {
            const double start_phase = cfg.start_phase_sigma_rad * n01(rng);
            for (double& p : phase) p += start_phase;
          }
          max_code = std::max(max_code, std::abs(code[kSub / 2]));
          max_freq = std::max(max_freq, std::abs((r.range_rate_mps - (c1 + c2 * T)) / kLambda));
          ChannelCorrelation cc;
          cc.prn = r.prn;
          cc.integration_time_s = T;
          cc.taps = ideal_correlation(code, phase, blocked ? 0.0 : A, d);
          const Eigen::Vector3d ni = L * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
          const Eigen::Vector3d nq = L * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
          for (int j = 0; j < 3; ++j) {
            cc.taps.i[j] += ni(j);
            cc.taps.q[j] += nq(j);
          }
          cc.cn0_dbhz = blocked ? 0.0 : cfg.cn0_dbhz;  // the channel's estimate: blocked = nothing there
          if (cfg.tell_start_phase) cc.start_phase_var_rad2 = cfg.start_phase_sigma_rad * cfg.start_phase_sigma_rad;
          if (cfg.pll_bw_hz > 0.0) {
            cc.has_replica = true;
            cc.replica_t_start_s = r.t_start_s;
            cc.replica_pseudorange_m = r.pseudorange_m;
            cc.replica_range_rate_mps = rep_rate;
            cc.continuous_carrier = cfg.tell_continuous_carrier;
            // The phase runs on to the period's end (exact quadratic signal); the PLL then steers the frequency
            // from the measured mean phase (its thermal jitter at Bn: the start-phase variance it leaves).
            pll.phase_rad += 2.0 * M_PI * (rep_rate * T - (p1 - p0)) / kLambda;
            const double theta = std::atan2(cc.taps.q[1], cc.taps.i[1]);
            pll.integrator_hz += wn * wn * theta * T / (2.0 * M_PI);
            pll.correction_hz = pll.integrator_hz + 2.0 * 0.707 * wn * theta / (2.0 * M_PI);
            if (!cfg.tell_start_phase)
              cc.start_phase_var_rad2 = 0.0;
            else
              cc.start_phase_var_rad2 = cfg.pll_bw_hz / std::pow(10.0, 0.1 * cfg.cn0_dbhz);
          }
          corr.push_back(cc);
        }
        timed([&] { integ.finish_period(corr); });
        for (const auto& u : integ.last_updates()) res.nis.push_back(u.nis);
        NominalState truth;
        truth.nav = run.truth[k].nav();
        truth.accel_bias_b = imu.accel_bias();
        truth.gyro_bias_b = imu.gyro_bias();
        const TruthClock ck = clock_at(t1);
        truth.clock_bias_m = ck.bias_m;
        truth.clock_drift_mps = ck.drift_mps;
        const StateVector<17> e = error_state<17>(integ.nominal(), truth);
        const Eigen::MatrixXd P = integ.covariance();
        res.last_error = e;
        res.last_sigma = P.diagonal().cwiseSqrt();
        res.t_s.push_back(t1);
        res.pos_err_m.push_back(e.segment<3>(ix::kPos));
        res.sigma_pos_m.push_back(integ.output().sigma_pos_ned_m);
        res.nees.push_back(e.dot(P.ldlt().solve(e)));
        res.max_code_err_chips.push_back(max_code);
        res.max_freq_err_hz.push_back(max_freq);
      }
      if (k == n_steps) break;
      timed([&] { replicas = integ.start_period(T); });
      int coasting = 0;
      for (const auto& r : replicas) coasting += r.coasting ? 1 : 0;
      res.coasting.push_back(coasting);
    }
    const ins::ImuIncrement measured = imu.apply(run.imu[k], imu_dt);
    timed([&] { integ.add_imu(measured); });
  }
  res.cpu_s = cpu;
  res.counters = integ.counters();
  return res;
}

}  // namespace ultratrack::fusion::test
