// SPDX-License-Identifier: GPL-3.0-or-later
// The INS trajectory simulator driving the synthesiser through InsTruthMotion: on a vehicle circling at
// 500 km/h with two antennas 1.2 m apart, the carrier phase difference between the antennas equals the
// baseline projected on the line of sight over the wavelength (the attitude receiver's observable), and the
// code timing of each antenna follows its own position.
#include "sim/ins_truth_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"
#include "signals/gps_constants.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::sim {
namespace {

TEST(InsTruthMotion, CarrierPhaseDifferenceBetweenAntennasIsBaselineOnLineOfSight) {
  const auto spec = ins::profile_spec("circle", 3.0, 35.274016 * io::kRadPerDeg, 137.013759 * io::kRadPerDeg, 100.0);
  auto truth = std::make_shared<ins::TruthInterpolator>(ins::simulate(spec, 100.0).truth);
  const std::vector<Eigen::Vector3d> levers = {{0.0, 0.0, -0.3}, {1.2, 0.0, -0.3}};
  auto motion = std::make_shared<InsTruthMotion>(truth, levers);
  ASSERT_EQ(motion->antenna_count(), 2);

  signals::SynthesiserOptions o;
  o.sample_rate_hz = 2e6;
  o.start = {2190, 518400.0};
  o.ionosphere = false;
  auto nominal = signals::nominal_constellation(o.start);
  signals::IfSynthesiser synth(o, nominal.ephemerides, motion);
  const auto views = synth.visible_satellites(0);
  ASSERT_GE(views.size(), 4u);
  for (std::int64_t sample : {std::int64_t{0}, std::int64_t{2'000'000}, std::int64_t{5'000'000}}) {
    for (const auto& v : views) {
      const auto t0 = synth.timing(v.prn, 0, sample);
      const auto t1 = synth.timing(v.prn, 1, sample);
      const double t_r = t0.receive_time_s;
      const auto a0 = motion->antenna_state(0, t_r), a1 = motion->antenna_state(1, t_r);
      EXPECT_NEAR((a1.r_e_m - a0.r_e_m).norm(), 1.2, 1e-6);
      // Line of sight from the satellite position at the transmit time (Sagnac-rotated).
      const auto eph = nominal.ephemerides[static_cast<std::size_t>(v.prn - 1)];
      const double flight = t0.geometric_range_m / signals::kSpeedOfLight_mps;
      const auto st = signals::satellite_state(eph, signals::add_seconds(o.start, t_r - flight));
      const Eigen::Vector3d u = (signals::rotate_to_receive_frame(st.r_e_m, flight) - a0.r_e_m).normalized();
      const double expected_cycles = u.dot(a1.r_e_m - a0.r_e_m) / signals::kL1Wavelength_m;
      EXPECT_NEAR(t1.carrier_phase_cycles - t0.carrier_phase_cycles, expected_cycles, 1e-3)
          << "PRN " << v.prn << " sample " << sample;
      EXPECT_NEAR(t0.pseudorange_m - t1.pseudorange_m, u.dot(a1.r_e_m - a0.r_e_m), 1e-3);
    }
  }
  // And the samples come out for both antennas.
  std::vector<std::complex<float>> x0(20000), x1(20000);
  std::vector<std::span<std::complex<float>>> spans{x0, x1};
  synth.generate(spans);
  EXPECT_NE(x0, x1);
}

}  // namespace
}  // namespace ultratrack::sim
