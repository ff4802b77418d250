// SPDX-License-Identifier: GPL-3.0-or-later
// Ultra-tight filter cost per integration period: replica prediction + I&Q updates of 8 satellites (EKF, UKF),
// the vehicle at rest, taps at their expected values at 45 dB-Hz (the cost does not depend on the values).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>

#include "fusion/ultratight_integration.hpp"
#include "ins/imu_error_model.hpp"
#include "signals/nominal_constellation.hpp"

namespace {

using namespace ultratrack;

void run(benchmark::State& state, fusion::FilterKind filter, fusion::UltraTightForm form) {
  const signals::GpsTime origin{2300, 200000.0};
  const auto constellation = signals::nominal_constellation(origin);
  ins::NavState nav;
  nav.lat_rad = 37.0 * M_PI / 180.0;
  nav.lon_rad = 127.0 * M_PI / 180.0;
  nav.height_m = 100.0;
  fusion::UltraTightOptions opt;
  opt.filter = filter;
  opt.form = form;
  opt.model = fusion::error_model_from_preset(ins::imu_preset("hg1700ae"));
  opt.gps_time_origin = origin;
  opt.gate.enabled = false;
  opt.tight.elevation_mask_rad = 0.0;  // enough satellites for 8 at this place and time
  fusion::UltraTightIntegration probe(nav, constellation.ephemerides, opt);
  std::vector<signals::Ephemeris> eph;
  for (const auto& r : probe.start_period(0.02))
    if (eph.size() < 8) eph.push_back(constellation.ephemerides[r.prn - 1]);
  fusion::UltraTightIntegration integ(nav, eph, opt);
  const fusion::IqSettings is{};
  const fusion::IqTaps taps = fusion::expected_iq(fusion::TrackingErrors{}, is);
  const Eigen::Vector3d g_up(0.0, 0.0, 9.80665 * 0.01);
  double t = 0.0;
  for (auto _ : state) {
    const auto& reps = integ.start_period(0.02);
    std::vector<fusion::ChannelCorrelation> corr;
    for (const auto& r : reps) corr.push_back({r.prn, taps, 45.0, 0.02, true});
    for (int k = 0; k < 2; ++k) {
      t += 0.01;
      integ.add_imu(ins::ImuIncrement{t, Eigen::Vector3d::Zero(), -g_up});
    }
    integ.finish_period(corr);
    state.counters["satellites"] = static_cast<double>(reps.size());
  }
}

void BM_UltraTightEkfIq8(benchmark::State& s) { run(s, fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq); }
void BM_UltraTightUkfIq8(benchmark::State& s) { run(s, fusion::FilterKind::Ukf, fusion::UltraTightForm::Iq); }
void BM_UltraTightEkfDiscriminator8(benchmark::State& s) {
  run(s, fusion::FilterKind::Ekf, fusion::UltraTightForm::Discriminator);
}
void BM_UltraTightUkfDiscriminator8(benchmark::State& s) {
  run(s, fusion::FilterKind::Ukf, fusion::UltraTightForm::Discriminator);
}
BENCHMARK(BM_UltraTightEkfIq8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_UltraTightUkfIq8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_UltraTightEkfDiscriminator8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_UltraTightUkfDiscriminator8)->Unit(benchmark::kMicrosecond);

}  // namespace
