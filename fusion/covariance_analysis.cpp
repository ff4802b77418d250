// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/covariance_analysis.hpp"

#include <cmath>
#include <numbers>

#include "fusion/ekf.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/iq_measurements.hpp"
#include "fusion/tight_measurements.hpp"
#include "ins/earth_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/look_angles.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kC = 299792458.0;
constexpr double kMicroG = 9.80665e-6;
constexpr double kDegPerHour = io::kRadPerSecPerDegPerHour;

// Satellites above the mask seen from the antenna at GPS time t, with the observables an error-free
// receiver on the truth would measure (so the innovation is zero).
std::vector<SatelliteObservable> visible_satellites(const std::vector<signals::Ephemeris>& ephemerides,
                                                    const signals::GpsTime& t, const Eigen::Vector3d& r_e,
                                                    const Eigen::Vector3d& v_e, const CovarianceAnalysisOptions& o) {
  std::vector<SatelliteObservable> out;
  for (int prn = 1; prn <= 32; ++prn) {
    const auto eph = signals::select_ephemeris(ephemerides, prn, t);
    if (!eph) continue;
    double tau = 0.075;
    signals::SatelliteState s;
    Eigen::Vector3d r_sat;
    for (int it = 0; it < 3; ++it) {  // light time
      s = signals::satellite_state(*eph, signals::add_seconds(t, -tau));
      r_sat = signals::rotate_to_receive_frame(s.r_e_m, tau);
      tau = (r_sat - r_e).norm() / kC;
    }
    const signals::LookAngles look = signals::look_angles(r_e, r_sat);
    if (look.elevation_rad < o.elevation_mask_rad) continue;
    SatelliteObservable sat;
    sat.prn = prn;
    sat.r_sat_e = r_sat;
    // velocity in the receive-time frame (the light-time rate terms do not change the geometry rows)
    sat.v_sat_e = signals::rotate_to_receive_frame(s.v_e_mps, tau);
    sat.elevation_rad = look.elevation_rad;
    sat.azimuth_rad = look.azimuth_rad;
    sat.sigma_range_m = o.sigma_range_m;
    sat.sigma_rate_mps = o.sigma_rate_mps;
    sat.pseudorange_m = predicted_pseudorange_m(sat, r_e, 0.0);
    sat.has_rate = o.use_range_rate;
    if (sat.has_rate) sat.range_rate_mps = predicted_range_rate_mps(sat, r_e, v_e, 0.0);
    out.push_back(sat);
  }
  return out;
}

// One measurement update at the truth (zero error): tight pseudoranges (rates), or ultra-tight I&Q taps /
// discriminator outputs as an error-free receiver on the truth would produce them.
template <class Filter>
void update(Filter& filter, const CovarianceAnalysisOptions& o, const NominalState& nominal,
            const std::vector<SatelliteObservable>& sats, const Eigen::Vector3d& w_ib_b) {
  const Eigen::Vector3d lever = Eigen::Vector3d::Zero();
  if (o.coupling == Coupling::kTight) {
    filter.update(EpochMeasurement17(nominal, sats, lever, w_ib_b, o.use_range_rate));
    return;
  }
  if (o.iq_form == IqForm::Iq) {
    const std::vector<IqTaps> taps(sats.size(), expected_iq(TrackingErrors{}, o.iq));
    filter.update(IqEpochMeasurement17(nominal, sats, lever, w_ib_b, o.iq, taps));
    return;
  }
  const DiscriminatorNoise n = discriminator_noise(o.iq, o.discriminator_squaring_loss);
  const double sr = o.discriminator_sigma_range_m > 0.0 ? o.discriminator_sigma_range_m : n.range_sigma_m;
  const double sv = o.discriminator_sigma_rate_mps > 0.0 ? o.discriminator_sigma_rate_mps : n.rate_sigma_mps;
  filter.update(DiscriminatorEpochMeasurement17(nominal, sats, lever, w_ib_b,
                                                Eigen::VectorXd::Zero(2 * static_cast<int>(sats.size())), sr, sv,
                                                o.discriminator_use_rate));
}

template <class Filter>
CovarianceAnalysisResult run(Filter& filter, const CovarianceAnalysisOptions& o) {
  const ins::TrajectorySpec spec = ins::profile_spec(o.trajectory, o.duration_s, o.lat_rad, o.lon_rad, o.height_m);
  ins::TrajectoryGenerator gen(spec, 1.0 / o.propagation_interval_s);
  InsErrorModel<17> model(o.model);
  const std::vector<signals::Ephemeris> ephemerides =
      o.ephemerides.empty() ? signals::nominal_constellation(o.start).ephemerides : o.ephemerides;
  CovarianceAnalysisResult result;
  auto sample = [&](double t, std::vector<Eigen::Vector3d> los) {
    CovarianceSample c;
    c.t_s = t;
    c.sigma_pos_ned_m = filter.P().diagonal().template head<3>().cwiseSqrt();
    c.satellites = static_cast<int>(los.size());
    c.los_ned = std::move(los);
    result.samples.push_back(std::move(c));
  };
  sample(0.0, {});
  double next_update = o.update_interval_s;
  while (!gen.done()) {
    const ins::TruthSample before = gen.truth();
    gen.advance();
    const ins::TruthSample& now = gen.truth();
    const double dt = now.t_s - before.t_s;
    // F at the interval's start: the INS runs on the truth (covariance analysis).
    model.set_linearisation({before.nav(), before.f_b, before.w_ib_b});
    filter.predict(model, dt);
    if (now.t_s + 1e-9 < next_update) continue;
    next_update += o.update_interval_s;
    const Eigen::Vector3d r_e = ins::ecef_from_geodetic(now.lat_rad, now.lon_rad, now.height_m);
    const Eigen::Vector3d v_e = ins::C_en(now.lat_rad, now.lon_rad) * now.v_n;
    const auto sats = visible_satellites(ephemerides, signals::add_seconds(o.start, now.t_s), r_e, v_e, o);
    if (sats.empty()) throw io::InputError("covariance analysis", "no satellite above the mask");
    NominalState nominal;
    nominal.nav = now.nav();
    model.set_linearisation({now.nav(), now.f_b, now.w_ib_b});
    update(filter, o, nominal, sats, now.w_ib_b);
    filter.set_x(StateVector<17>::Zero());  // closed loop: the (zero) estimate is fed back
    std::vector<Eigen::Vector3d> los;
    const Eigen::Matrix3d C_ne = ins::C_en(now.lat_rad, now.lon_rad).transpose();
    for (const auto& sat : sats) los.push_back(C_ne * (sat.r_sat_e - r_e).normalized());
    sample(now.t_s, std::move(los));
  }
  return result;
}

}  // namespace

InsErrorModelOptions seed001_eq38_model() {
  InsErrorModelOptions m;
  m.accel.bias_model = BiasModel::RandomConstant;
  m.accel.bias_sigma = 500.0 * kMicroG;
  m.accel.white_noise_psd = std::pow(100.0 * kMicroG, 2);
  m.gyro.bias_model = BiasModel::RandomConstant;
  m.gyro.bias_sigma = 3.0 * kDegPerHour;
  m.gyro.white_noise_psd = std::pow(0.1 * kDegPerHour, 2);
  m.clock.bias_psd_m2_per_s = 0.0;
  m.clock.drift_psd_m2_per_s3 = 0.0;
  m.clock.bias_sigma_m = 10.0;
  m.clock.drift_sigma_mps = 1.0;
  m.discretisation = Discretisation::VanLoan;
  return m;
}

CovarianceAnalysisOptions seed001_covariance_options(const std::string& trajectory, FilterKind filter) {
  CovarianceAnalysisOptions o;
  o.trajectory = trajectory;
  o.filter = filter;
  o.model = seed001_eq38_model();
  return o;
}

CovarianceAnalysisOptions seed001_ultratight_options(const std::string& trajectory, FilterKind filter, IqForm form) {
  CovarianceAnalysisOptions o = seed001_covariance_options(trajectory, filter);
  o.coupling = Coupling::kUltraTight;
  o.iq_form = form;
  o.update_interval_s = o.iq.integration_time_s;
  o.propagation_interval_s = o.iq.integration_time_s;
  return o;
}

CovarianceSample CovarianceAnalysisResult::at(double t_s) const {
  CovarianceSample best;
  for (const auto& s : samples)
    if (s.t_s <= t_s + 1e-9) best = s;
  return best;
}

CovarianceAnalysisResult run_covariance_analysis(const CovarianceAnalysisOptions& o) {
  if (o.coupling != Coupling::kTight && o.coupling != Coupling::kUltraTight)
    throw io::InputError("covariance analysis", "the coupling must be tight or ultra-tight");
  if (!(o.duration_s > 0.0) || !(o.propagation_interval_s > 0.0) || !(o.update_interval_s > 0.0))
    throw io::InputError("covariance analysis", "durations and intervals must be positive");
  if (!(o.sigma_range_m > 0.0) || !(o.sigma_rate_mps > 0.0))
    throw io::InputError("covariance analysis", "measurement sigmas must be positive");
  InsErrorModel<17> model(o.model);
  const StateMatrix<17> P0 = model.initial_covariance(o.sigma_pos_ned_m, o.sigma_vel_n_mps, o.sigma_att_rad);
  GateOptions no_gate;
  no_gate.enabled = false;
  if (o.filter == FilterKind::Ekf) {
    Ekf<17> f(StateVector<17>::Zero(), P0, EkfOptions{o.model.discretisation, no_gate});
    return run(f, o);
  }
  Ukf<17> f(StateVector<17>::Zero(), P0, UkfOptions{o.ukf, o.model.discretisation, no_gate});
  return run(f, o);
}

}  // namespace ultratrack::fusion
