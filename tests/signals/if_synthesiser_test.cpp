// SPDX-License-Identifier: GPL-3.0-or-later
// The IF synthesiser against independent truth: a brute-force acquisition written in the test finds every
// visible satellite at the Doppler, code phase and C/N0 the synthesiser states; noise and gain levels
// follow the documented convention; the pseudorange implied by the synthesised code equals the
// receiver-side model range + c (b - dt_sv) + I + T; synthesised samples follow the exact timing.
#include "signals/if_synthesiser.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <numeric>

#include "io/units.hpp"
#include "io/why_invalid.hpp"
#include "signals/atmosphere.hpp"
#include "signals/sample_reader.hpp"
#include "signals/sample_writer.hpp"
#include "signals/satellite_state.hpp"
#include "support/brute_force_acquisition.hpp"
#include "support/test_data.hpp"

namespace ultratrack::signals {
namespace {

using test_support::BruteForceAcquisition;
using test_support::ecef_from_llh;
using test_support::walker_constellation;

const GpsTime kStart{2190, 518400.0};

SynthesiserOptions base_options(double fs) {
  SynthesiserOptions o;
  o.sample_rate_hz = fs;
  o.start = kStart;
  o.klobuchar.valid = true;
  o.klobuchar.alpha[0] = 1.1176e-8;
  o.klobuchar.alpha[1] = -7.4506e-9;
  o.klobuchar.alpha[2] = -5.9605e-8;
  o.klobuchar.alpha[3] = 1.1921e-7;
  o.klobuchar.beta[0] = 8.8064e-4;
  o.klobuchar.beta[1] = -3.2768e4;
  o.klobuchar.beta[2] = -1.9661e5;
  o.klobuchar.beta[3] = 1.9661e5;
  o.ionosphere = true;
  o.troposphere = true;
  o.clock.bias_s = 2.5e-4;
  o.clock.drift_sps = 3.0e-7;
  return o;
}

std::shared_ptr<StaticMotion> static_receiver() {
  return std::make_shared<StaticMotion>(std::vector<Eigen::Vector3d>{ecef_from_llh(35.274016, 137.013759, 100.0)});
}

std::vector<std::complex<float>> synthesise(IfSynthesiser& synth, std::size_t n, std::size_t chunk = 3001) {
  std::vector<std::complex<float>> x(n);
  for (std::size_t done = 0; done < n;) {
    const std::size_t c = std::min(chunk, n - done);
    std::span<std::complex<float>> s(x.data() + done, c);
    synth.generate(std::span<const std::span<std::complex<float>>>(&s, 1));
    done += c;
  }
  return x;
}

// Through the file formats, as a receiver would see it.
std::vector<std::complex<float>> via_file(const std::vector<std::complex<float>>& x, SampleFormat format) {
  const auto path = test::scratch_dir() / "synth.bin";
  SampleWriter w(path, format);
  w.write(x);
  w.finish();
  SampleReader r(path, format);
  std::vector<std::complex<float>> y(x.size());
  EXPECT_EQ(r.read(y), y.size());
  return y;
}

double wrap_chips(double d) { return d - 1023.0 * std::round(d / 1023.0); }

TEST(IfSynthesiser, BruteForceAcquisitionFindsEverySatelliteAtStatedDopplerCodePhaseAndCn0) {
  auto o = base_options(2.048e6);
  o.cn0_dbhz_by_prn = {{1, 41.0}, {5, 48.0}, {9, 44.0}, {13, 40.0}, {17, 50.0}, {21, 43.0}};
  o.default_cn0_dbhz = 45.0;
  IfSynthesiser synth(o, walker_constellation(kStart), static_receiver());
  const auto views = synth.visible_satellites(0);
  ASSERT_GE(views.size(), 5u) << "test constellation should show several satellites";
  const auto x = via_file(synthesise(synth, 2048 * 120), SampleFormat::i8);
  BruteForceAcquisition acq(x, o.sample_rate_hz);
  for (const auto& v : views) {
    SCOPED_TRACE("PRN " + std::to_string(v.prn));
    const auto r = acq.acquire(v.prn);
    ASSERT_TRUE(r.found) << "peak ratio " << r.peak_ratio;
    // FLL-type estimate over 60 ms at >= 40 dB-Hz: a few Hz of noise; 25 Hz is > 3 sigma.
    EXPECT_NEAR(r.doppler_hz, v.doppler_hz, 25.0);
    // 0.01 chip search grid, 20 ms of prompt power: 0.05 chip covers grid and noise.
    EXPECT_NEAR(wrap_chips(r.code_phase_chips - v.code_phase_chips), 0.0, 0.05);
    // The 1.5 dB: 100 x 1 ms prompt powers give sigma 0.2 dB at 40 dB-Hz, and the off-peak floor
    // holds the other satellites' cross-correlation (up to -1 dB here; the single-satellite test below
    // checks the level tightly).
    EXPECT_NEAR(r.cn0_dbhz, v.cn0_dbhz, 1.5);
    std::printf("PRN %2d el %5.1f deg: doppler %9.2f / %9.2f Hz  code %8.3f / %8.3f chips  C/N0 %5.2f / %5.2f dB-Hz\n",
                v.prn, v.elevation_rad / io::kRadPerDeg, r.doppler_hz, v.doppler_hz, r.code_phase_chips,
                v.code_phase_chips, r.cn0_dbhz, v.cn0_dbhz);
  }
  // A satellite that is not transmitted is not found (its best cell is noise or another satellite's
  // cross-correlation, which the confirmation stage measures far below 30 dB-Hz).
  std::vector<int> absent;
  for (int prn = 25; prn <= 32; ++prn) absent.push_back(prn);
  for (int prn : absent) {
    const auto r = acq.acquire(prn);
    EXPECT_FALSE(r.found) << "PRN " << prn << " peak ratio " << r.peak_ratio << " C/N0 " << r.cn0_dbhz;
  }
}

TEST(IfSynthesiser, RealIfOutputIsAcquiredAfterMixingDown) {
  auto o = base_options(4.096e6);
  o.real_output = true;
  o.if_hz = 1.25e6;
  // Mixed down, the real signal's images (at -2 IF) join the other satellites' cross-correlation in the
  // off-peak floor; at 42 dB-Hz that bias stays below 1 dB (the level itself is checked alone below).
  o.default_cn0_dbhz = 42.0;
  IfSynthesiser synth(o, walker_constellation(kStart), static_receiver());
  const auto views = synth.visible_satellites(0);
  ASSERT_GE(views.size(), 5u);
  auto x = via_file(synthesise(synth, 4096 * 110), SampleFormat::r8);
  for (std::size_t n = 0; n < x.size(); ++n) {
    EXPECT_EQ(x[n].imag(), 0.0f);
    x[n] = x[n].real() *
           std::polar(1.0f, static_cast<float>(-2 * std::numbers::pi * std::fmod(o.if_hz * n / o.sample_rate_hz, 1.0)));
  }
  BruteForceAcquisition acq(x, o.sample_rate_hz);
  for (const auto& v : views) {
    SCOPED_TRACE("PRN " + std::to_string(v.prn));
    const auto r = acq.acquire(v.prn);
    ASSERT_TRUE(r.found) << "peak ratio " << r.peak_ratio;
    EXPECT_NEAR(r.doppler_hz, v.doppler_hz, 25.0);
    EXPECT_NEAR(wrap_chips(r.code_phase_chips - v.code_phase_chips), 0.0, 0.05);
    EXPECT_NEAR(r.cn0_dbhz, v.cn0_dbhz, 1.5);
  }
}

// One satellite alone (no multiple-access interference in the floor): the estimate must match tightly.
// 200 x 1 ms prompts at 40 dB-Hz: sigma of the estimate about 0.13 dB; 0.4 dB is 3 sigma.
TEST(IfSynthesiser, SingleSatelliteCn0MatchesWithinNoise) {
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(base_options(2.048e6), eph, static_receiver());
  const auto views = probe.visible_satellites(0);
  for (double cn0 : {40.0, 44.0, 48.0}) {
    auto o = base_options(2.048e6);
    o.default_cn0_dbhz = cn0;
    IfSynthesiser synth(o, {eph[views[1].prn - 1]}, static_receiver());
    const auto x = via_file(synthesise(synth, 2048 * 215), SampleFormat::i8);
    const auto r = BruteForceAcquisition(x, o.sample_rate_hz).acquire(views[1].prn, 200);
    ASSERT_TRUE(r.found);
    EXPECT_NEAR(r.cn0_dbhz, cn0, 0.4);
    std::printf("single satellite: C/N0 %.2f measured for %.1f requested\n", r.cn0_dbhz, cn0);
  }
  // Real output at an IF, mixed down in the test: the documented real-signal amplitude gives the same C/N0.
  auto o = base_options(4.096e6);
  o.real_output = true;
  o.if_hz = 1.25e6;
  o.default_cn0_dbhz = 44.0;
  IfSynthesiser synth(o, {eph[views[1].prn - 1]}, static_receiver());
  auto x = via_file(synthesise(synth, 4096 * 215), SampleFormat::r16);
  for (std::size_t n = 0; n < x.size(); ++n)
    x[n] = x[n].real() *
           std::polar(1.0f, static_cast<float>(-2 * std::numbers::pi * std::fmod(o.if_hz * n / o.sample_rate_hz, 1.0)));
  const auto r = BruteForceAcquisition(x, o.sample_rate_hz).acquire(views[1].prn, 200);
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.cn0_dbhz, 44.0, 0.4);
  std::printf("single satellite, real IF output: C/N0 %.2f measured for 44.0 requested\n", r.cn0_dbhz);
}

double variance(const std::vector<std::complex<float>>& x, bool imag) {
  double s = 0, s2 = 0;
  for (const auto& v : x) {
    const double a = imag ? v.imag() : v.real();
    s += a;
    s2 += a * a;
  }
  const double n = static_cast<double>(x.size());
  return s2 / n - (s / n) * (s / n);
}

TEST(IfSynthesiser, NoiseHasTheConfiguredSigmaPerComponent) {
  auto o = base_options(2.0e6);
  o.output_rms = 20.0;
  for (auto format : {SampleFormat::f32, SampleFormat::i8, SampleFormat::r16}) {
    SCOPED_TRACE(std::string(to_string(format)));
    o.real_output = !is_complex(format);
    o.if_hz = o.real_output ? 0.5e6 : 0.0;
    IfSynthesiser synth(o, {}, static_receiver());  // no satellites: noise only
    EXPECT_DOUBLE_EQ(synth.noise_sigma(), 20.0);
    const auto x = via_file(synthesise(synth, 400000), format);
    // Uniform quantisation adds 1/12 LSB^2 (integer formats); sample variance has sigma^2 sqrt(2/N) = 0.22 %.
    const double expected = 400.0 + (format == SampleFormat::f32 ? 0.0 : 1.0 / 12.0);
    EXPECT_NEAR(variance(x, false) / expected, 1.0, 0.01);
    if (o.real_output) {
      EXPECT_EQ(variance(x, true), 0.0);
    } else {
      EXPECT_NEAR(variance(x, true) / expected, 1.0, 0.01);
      double cross = 0;
      for (const auto& v : x) cross += static_cast<double>(v.real()) * v.imag();
      EXPECT_NEAR(cross / x.size() / expected, 0.0, 0.01);  // I and Q independent
    }
    double lag1 = 0;
    for (std::size_t i = 1; i < x.size(); ++i) lag1 += static_cast<double>(x[i].real()) * x[i - 1].real();
    EXPECT_NEAR(lag1 / x.size() / expected, 0.0, 0.01);  // white
  }
}

TEST(IfSynthesiser, AutomaticGainPutsTotalPowerAtOutputRmsAndAmplitudeFollowsCn0) {
  auto o = base_options(2.0e6);
  o.output_rms = 127.0 / 4.0;
  o.default_cn0_dbhz = 55.0;  // strong enough that the signals add visibly to the power
  IfSynthesiser synth(o, walker_constellation(kStart), static_receiver());
  const auto views = synth.visible_satellites(0);
  const double a = synth.amplitude(views.front().prn);
  const double sigma = synth.noise_sigma();
  // Documented convention: A^2 / (2 sigma^2) = (C/N0) / fs for complex output.
  EXPECT_NEAR(a * a / (2 * sigma * sigma), std::pow(10.0, 5.5) / o.sample_rate_hz, 1e-12);
  EXPECT_NEAR(sigma * sigma * (1 + views.size() * std::pow(10.0, 5.5) / o.sample_rate_hz), o.output_rms * o.output_rms,
              1e-6);
  const auto x = synthesise(synth, 400000);
  EXPECT_NEAR((variance(x, false) + variance(x, true)) / 2 / (o.output_rms * o.output_rms), 1.0, 0.01);
}

TEST(IfSynthesiser, SameSeedGivesSameSamplesOtherSeedDiffers) {
  auto o = base_options(2.0e6);
  o.clock.drift_noise_sps_per_sqrt_s = 1e-9;
  o.clock.bias_noise_s_per_sqrt_s = 1e-10;
  IfSynthesiser a(o, walker_constellation(kStart), static_receiver());
  IfSynthesiser b(o, walker_constellation(kStart), static_receiver());
  o.seed = 2;
  IfSynthesiser c(o, walker_constellation(kStart), static_receiver());
  const auto xa = synthesise(a, 30000, 1000), xb = synthesise(b, 30000, 7777), xc = synthesise(c, 30000);
  // The chunking changes nothing but the rounding of the carrier phase word where a chunk starts: at
  // most one 4096-entry table bin per satellite.
  double bound = 0;
  for (const auto& v : a.visible_satellites(0)) bound += a.amplitude(v.prn) * 2 * std::numbers::pi / 4096 * 1.01;
  double worst = 0, differ = 0;
  for (std::size_t i = 0; i < xa.size(); ++i) {
    worst = std::max(worst, static_cast<double>(std::abs(xa[i] - xb[i])));
    differ += std::abs(xa[i] - xc[i]) > 1.0f;
  }
  EXPECT_LT(worst, bound);
  EXPECT_GT(differ, 0.9 * xa.size());
  EXPECT_EQ(a.receiver_clock(25000).bias_s, b.receiver_clock(25000).bias_s);
}

// The receiver-side model, written from the standard (not from the synthesiser): given the pseudorange,
// the receive time of the receiver clock and the clock error, recompute the transmit time, satellite
// position, Sagnac rotation, SV clock and atmosphere; the model pseudorange must equal the synthesised one.
TEST(IfSynthesiser, PseudorangeEqualsRangePlusClockTermsPlusDelays) {
  auto o = base_options(4.0e6);
  const Eigen::Vector3d r_rx = ecef_from_llh(35.274016, 137.013759, 100.0);
  IfSynthesiser synth(o, walker_constellation(kStart), static_receiver());
  double lat = 0, lon = 0, h = 0;
  GeographicLib::Geocentric::WGS84().Reverse(r_rx.x(), r_rx.y(), r_rx.z(), lat, lon, h);
  for (const auto& v : synth.visible_satellites(0)) {
    for (std::int64_t sample : {std::int64_t{0}, std::int64_t{1234567}, std::int64_t{40'000'123}}) {
      const SignalTiming t = synth.timing(v.prn, 0, sample);
      const double tau = sample / o.sample_rate_hz;
      const double b = o.clock.bias_s + o.clock.drift_sps * tau;
      // Receiver clock reading and pseudorange from the synthesised SV time of the code.
      const GpsTime t_rx_clock = add_seconds(kStart, o.clock.bias_s + tau);
      EXPECT_NEAR(t.rx_clock_s, o.clock.bias_s + tau, 1e-15);
      const double rho = t.pseudorange_m;
      // Transmit time by the SV clock, then GPS time by the L1 C/A clock correction (iterated once).
      const GpsTime t_sv = add_seconds(t_rx_clock, -rho / kSpeedOfLight_mps);
      const auto eph = walker_constellation(kStart)[v.prn - 1];
      double dt_sv = l1_ca_clock_correction_s(eph, t_sv);
      dt_sv = l1_ca_clock_correction_s(eph, add_seconds(t_sv, -dt_sv));
      const GpsTime t_tx = add_seconds(t_sv, -dt_sv);
      const SatelliteState st = satellite_state(eph, t_tx);
      const double flight = seconds_between(add_seconds(t_rx_clock, -b), t_tx);
      const Eigen::Vector3d r_sat = rotate_to_receive_frame(st.r_e_m, flight);
      const double range = (r_sat - r_rx).norm();
      const Eigen::Vector3d u = (r_sat - r_rx).normalized();
      const Eigen::Vector3d up(std::cos(lat * io::kRadPerDeg) * std::cos(lon * io::kRadPerDeg),
                               std::cos(lat * io::kRadPerDeg) * std::sin(lon * io::kRadPerDeg),
                               std::sin(lat * io::kRadPerDeg));
      const Eigen::Vector3d east(-std::sin(lon * io::kRadPerDeg), std::cos(lon * io::kRadPerDeg), 0.0);
      const Eigen::Vector3d north = up.cross(east);
      const double el = std::asin(u.dot(up));
      double az = std::atan2(u.dot(east), u.dot(north));
      if (az < 0) az += 2 * std::numbers::pi;
      const double iono_m =
          kSpeedOfLight_mps * klobuchar_delay_s(o.klobuchar, lat * io::kRadPerDeg, lon * io::kRadPerDeg, az, el,
                                                add_seconds(t_rx_clock, -b).tow_s);
      const double tropo_m = troposphere_delay_m(lat * io::kRadPerDeg, h, el);
      const double model = range + kSpeedOfLight_mps * (b - dt_sv) + iono_m + tropo_m;
      EXPECT_NEAR(rho - model, 0.0, 1e-4) << "PRN " << v.prn << " sample " << sample;
      EXPECT_NEAR(t.geometric_range_m, range, 1e-4);
      EXPECT_NEAR(t.iono_delay_m, iono_m, 1e-6);
      EXPECT_NEAR(t.tropo_delay_m, tropo_m, 1e-6);
      EXPECT_GT(iono_m, 0.5);  // the delays are really in (Klobuchar at night: a few metres)
      EXPECT_GT(tropo_m, 2.0);
    }
  }
}

// Doppler against the range rate from the satellite velocity: -(u . (v_sat - v_rx)) / lambda - f_L1 * drift
// + f_L1 * (SV clock drift). Neglected: light-time and Sagnac rate terms (< 0.05 Hz).
TEST(IfSynthesiser, DopplerIsRangeRatePlusClockDrifts) {
  auto o = base_options(4.0e6);
  o.clock.drift_sps = -4.0e-7;
  const Eigen::Vector3d r_rx = ecef_from_llh(35.274016, 137.013759, 100.0);
  IfSynthesiser synth(o, walker_constellation(kStart), static_receiver());
  for (const auto& v : synth.visible_satellites(0)) {
    const auto eph = walker_constellation(kStart)[v.prn - 1];
    const SignalTiming t = synth.timing(v.prn, 0, 0);
    const GpsTime t_tx = add_seconds(kStart, t.code_sv_time_s - t.sv_clock_s);
    const SatelliteState st = satellite_state(eph, t_tx);
    const Eigen::Vector3d u = (rotate_to_receive_frame(st.r_e_m, 0.07) - r_rx).normalized();
    const double range_rate = u.dot(st.v_e_mps);
    const double expected =
        -range_rate / kL1Wavelength_m - kL1Frequency_hz * o.clock.drift_sps + kL1Frequency_hz * st.clock_drift_sps;
    EXPECT_NEAR(v.doppler_hz, expected, 0.1) << "PRN " << v.prn;
  }
}

// Noise off, data off: every sample equals amplitude * chip * exp(j 2 pi phase) at the exact phases,
// within the carrier table's half-bin (1.2e-4 cycle) plus interpolation; checked on a static antenna and
// on a second antenna accelerating at 30 m/s^2.
TEST(IfSynthesiser, SamplesFollowTheExactTimingOnEveryAntenna) {
  auto o = base_options(2.6e6);
  o.noise = false;
  o.nav_data = false;
  o.output_rms = 1.0;
  o.if_hz = 0.2e6;
  const Eigen::Vector3d r0 = ecef_from_llh(35.274016, 137.013759, 100.0);
  const Eigen::Vector3d east(-std::sin(137.013759 * io::kRadPerDeg), std::cos(137.013759 * io::kRadPerDeg), 0.0);
  std::vector<TrajectorySample> traj;
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.05 * i;
    traj.push_back({t, r0 + east * (10.0 + 0.5 * 30.0 * t * t), east * (30.0 * t)});
  }
  struct TwoAntennas final : ReceiverMotion {
    Eigen::Vector3d fixed;
    TrajectoryMotion moving;
    TwoAntennas(Eigen::Vector3d f, std::vector<TrajectorySample> s) : fixed(f), moving(std::move(s)) {}
    int antenna_count() const override { return 2; }
    AntennaState antenna_state(int a, double t) const override {
      return a == 0 ? AntennaState{fixed, Eigen::Vector3d::Zero()} : moving.antenna_state(0, t);
    }
  };
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(o, eph, static_receiver());
  const int prn = probe.visible_satellites(0).front().prn;
  IfSynthesiser synth(o, {eph[prn - 1]}, std::make_shared<TwoAntennas>(r0, traj));
  const double amp = synth.amplitude(prn);
  const std::size_t n = 2600 * 300;
  std::vector<std::complex<float>> a0(n), a1(n);
  std::vector<std::span<std::complex<float>>> spans{a0, a1};
  synth.generate(spans);
  const auto& code = ca_code(prn);
  for (int antenna = 0; antenna < 2; ++antenna) {
    const auto& x = antenna == 0 ? a0 : a1;
    double worst = 0;
    int checked = 0;
    for (std::size_t i = 1300; i < n; i += 7919) {
      const SignalTiming t = synth.timing(prn, antenna, static_cast<std::int64_t>(i));
      const double frac = t.code_phase_chips - std::floor(t.code_phase_chips);
      if (frac < 0.01 || frac > 0.99) continue;  // too close to a chip edge to know the chip
      const double chip = code[static_cast<int>(t.code_phase_chips)];
      const std::complex<double> got(x[i].real(), x[i].imag());
      EXPECT_NEAR(std::abs(got), amp, amp * 2e-3);
      const double phase = std::arg(got * chip) / (2 * std::numbers::pi);
      double d = phase - (t.carrier_phase_cycles - std::floor(t.carrier_phase_cycles));
      d -= std::round(d);
      worst = std::max(worst, std::abs(d));
      ++checked;
    }
    EXPECT_GT(checked, 80);
    EXPECT_LT(worst, 3e-4) << "antenna " << antenna;
    std::printf("antenna %d: worst carrier phase error %.2e cycles over %d samples\n", antenna, worst, checked);
  }
}

// The synthesised carrier phase minus the exact timing's, cycles, at the middle of each of the first `count`
// milliseconds (moved off chip edges, where the chip is unknown), unwrapped. Noise-free, one satellite.
std::vector<double> carrier_error_per_ms(IfSynthesiser& synth, const std::vector<std::complex<float>>& x, int prn,
                                         double fs, std::size_t count) {
  const auto& code = ca_code(prn);
  const auto half_ms = static_cast<std::size_t>(fs * 0.5e-3);
  std::vector<double> error;
  double unwrapped = 0.0;
  for (std::size_t ms = 0; ms < count; ++ms) {
    std::size_t i = (2 * ms + 1) * half_ms;
    SignalTiming t = synth.timing(prn, 0, static_cast<std::int64_t>(i));
    for (int tries = 0; tries < 20; ++tries) {
      const double frac = t.code_phase_chips - std::floor(t.code_phase_chips);
      if (frac > 0.05 && frac < 0.95) break;
      t = synth.timing(prn, 0, static_cast<std::int64_t>(++i));
    }
    const double chip = code[static_cast<int>(t.code_phase_chips)];
    double d = std::arg(std::complex<double>(x[i]) * chip) / (2 * std::numbers::pi) - t.carrier_phase_cycles;
    d -= std::round(d - unwrapped);
    unwrapped = d;
    error.push_back(d);
  }
  return error;
}

// Another generator's convention: exact parameters every 0.1 s, the code rate and carrier frequency of each
// interval's first millisecond held until the next. Under a constant carrier acceleration fdot (cycles/s^2)
// the integrated carrier then falls behind the geometry by fdot U (h - U) / 2 per interval (U = 0.1 s, h = 1 ms):
// the held frequency is the interval's start value, the true one grows through it. Measured per millisecond
// against the exact timing, noise-free, on an antenna accelerating at 5 m/s^2.
TEST(IfSynthesiser, HeldParametersLagTheGeometryByTheClosedForm) {
  auto o = base_options(0.5e6);
  o.noise = false;
  o.nav_data = false;
  o.output_rms = 1.0;
  o.parameter_update_s = 0.1;
  const Eigen::Vector3d r0 = ecef_from_llh(35.274016, 137.013759, 100.0);
  const Eigen::Vector3d east(-std::sin(137.013759 * io::kRadPerDeg), std::cos(137.013759 * io::kRadPerDeg), 0.0);
  std::vector<TrajectorySample> traj;
  for (int i = 0; i <= 30; ++i) {
    const double t = 0.05 * i;
    traj.push_back({t, r0 + east * (0.5 * 5.0 * t * t), east * (5.0 * t)});
  }
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(o, eph, static_receiver());
  // The satellite whose line of sight is most along east: the largest carrier acceleration.
  int prn = 0;
  double best = 0.0;
  for (const SatelliteView& v : probe.visible_satellites(0)) {
    const double along_east = std::abs(std::cos(v.elevation_rad) * std::sin(v.azimuth_rad));
    if (along_east > best) best = along_east, prn = v.prn;
  }
  IfSynthesiser synth(o, {eph[static_cast<std::size_t>(prn - 1)]}, std::make_shared<TrajectoryMotion>(traj));
  const double fs = o.sample_rate_hz;
  const std::size_t n = static_cast<std::size_t>(1.2 * fs);
  const std::vector<std::complex<float>> x = synthesise(synth, n);
  const auto carrier = [&](double t) { return synth.timing(prn, 0, std::llround(t * fs)).carrier_phase_cycles; };
  const double fdot = (carrier(0.6 + 0.1) - 2.0 * carrier(0.6) + carrier(0.6 - 0.1)) / 0.01;
  const std::vector<double> error_ms = carrier_error_per_ms(synth, x, prn, fs, 1200);
  const double per_interval = 0.5 * fdot * 0.1 * (1e-3 - 0.1);
  std::printf("held parameters: PRN %d, carrier acceleration %.2f Hz/s, lag %.4f cycles per 0.1 s\n", prn, fdot,
              per_interval);
  ASSERT_GT(std::abs(per_interval), 0.05);  // a geometry that shows the effect
  for (int k = 1; k <= 11; ++k) {
    const double measured = error_ms[100 * static_cast<std::size_t>(k)] - error_ms[0];
    // Within the interval's first millisecond the held and exact phases differ by < fdot h^2 / 2 (< 1e-4).
    EXPECT_NEAR(measured, k * per_interval, 0.02 * std::abs(k * per_interval) + 2e-3) << "after " << k << " intervals";
    if (k == 10) std::printf("after 1 s: %.4f cycles measured, %.4f closed form\n", measured, k * per_interval);
  }
}

// Held parameters are the generator's geometry; the front end's oscillator noise stays on every block: with a
// TCXO clock (phase wander ~0.15 cycles per 0.1 s) the synthesised carrier still follows the exact (noisy-clock)
// timing to within the geometric hold lag, which a held clock noise would exceed by cycles.
TEST(IfSynthesiser, HeldParametersKeepTheOscillatorNoiseOnEveryBlock) {
  auto o = base_options(0.5e6);
  o.noise = false;
  o.nav_data = false;
  o.output_rms = 1.0;
  o.parameter_update_s = 0.1;
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(o, eph, static_receiver());
  const int prn = probe.visible_satellites(0).front().prn;
  const double fs = o.sample_rate_hz;
  // The geometric carrier acceleration, from a clock without noise.
  IfSynthesiser quiet(o, {eph[static_cast<std::size_t>(prn - 1)]}, static_receiver());
  const auto quiet_carrier = [&](double t) { return quiet.timing(prn, 0, std::llround(t * fs)).carrier_phase_cycles; };
  const double fdot = (quiet_carrier(0.6) - 2.0 * quiet_carrier(0.5) + quiet_carrier(0.4)) / 0.01;
  o.clock.bias_noise_s_per_sqrt_s = std::sqrt(2e-19 / 2.0);                                           // TCXO h0
  o.clock.drift_noise_sps_per_sqrt_s = std::sqrt(2.0 * std::numbers::pi * std::numbers::pi * 2e-20);  // h-2
  IfSynthesiser synth(o, {eph[static_cast<std::size_t>(prn - 1)]}, static_receiver());
  const std::vector<std::complex<float>> x = synthesise(synth, static_cast<std::size_t>(1.05 * fs));
  const std::vector<double> error = carrier_error_per_ms(synth, x, prn, fs, 1001);
  double worst = 0.0;
  for (std::size_t ms = 0; ms < error.size(); ++ms) {
    const double lag = 0.5 * fdot * 0.1 * (1e-3 - 0.1) * (static_cast<double>(ms) / 100.0);  // at most one interval off
    worst = std::max(worst, std::abs(error[ms] - error[0] - lag));
  }
  std::printf("held parameters with a TCXO clock: worst carrier error beyond the hold lag %.4f cycles\n", worst);
  // Within an interval the linear lag model is off by at most |fdot| U^2 / 2 (~0.01 cycles here).
  EXPECT_LT(worst, 0.5 * std::abs(fdot) * 0.01 + 0.01);
}

// The data bits sit at the satellite's time: the symbol received at a sample whose code left the
// satellite at SV time t is bit floor((t - subframe start) / 20 ms) of the LNAV subframe that starts at the
// 6 s boundary before t (as the LNAV encoder builds it), +1 for bit 0. Noise-free, one satellite, 1.5 s.
TEST(IfSynthesiser, DataBitsFollowTheSatelliteTime) {
  auto o = base_options(1.024e6);
  o.noise = false;
  o.output_rms = 1.0;
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(o, eph, static_receiver());
  const int prn = probe.visible_satellites(0).front().prn;
  IfSynthesiser synth(o, {eph[prn - 1]}, static_receiver());
  const auto x = synthesise(synth, static_cast<std::size_t>(1.5 * o.sample_rate_hz));
  const LnavTransmitter tx(eph[prn - 1], o.klobuchar, o.utc, {eph[prn - 1]});
  const auto& code = ca_code(prn);
  const double t_sv0 = synth.timing(prn, 0, 0).code_sv_time_s;
  int checked = 0, flips = 0, previous = 0;
  for (int k = static_cast<int>(std::ceil(t_sv0 / 0.02)); k < 70; ++k) {
    // The sample whose code left the satellite in the middle of bit k (relative SV time 0.02 k + 0.01).
    const double target = 0.02 * k + 0.01;
    auto n = static_cast<std::int64_t>(std::llround((target - t_sv0) * o.sample_rate_hz));
    n += static_cast<std::int64_t>(std::llround((target - synth.timing(prn, 0, n).code_sv_time_s) * o.sample_rate_hz));
    if (n >= static_cast<std::int64_t>(x.size())) break;
    const SignalTiming t = synth.timing(prn, 0, n);
    const double frac = t.code_phase_chips - std::floor(t.code_phase_chips);
    if (frac < 0.01 || frac > 0.99) ++n;  // one sample on: away from the chip edge (0.5 chip per sample)
    const SignalTiming u = synth.timing(prn, 0, n);
    const std::complex<double> wiped = std::complex<double>(x[n].real(), x[n].imag()) *
                                       std::polar(1.0, -2 * std::numbers::pi * u.carrier_phase_cycles) *
                                       static_cast<double>(code[static_cast<int>(u.code_phase_chips)]);
    const int symbol = wiped.real() > 0 ? 1 : -1;
    EXPECT_GT(std::abs(wiped.real()), 0.99 * synth.amplitude(prn));
    // Expected: the transmitted bit at SV time start + u.code_sv_time_s.
    const GpsTime t_sv = add_seconds(kStart, u.code_sv_time_s);
    const GpsTime sf_start{t_sv.week, 6.0 * std::floor(t_sv.tow_s / 6.0)};
    const int bit = static_cast<int>(std::floor((t_sv.tow_s - sf_start.tow_s) / 0.02));
    const int expected = tx.subframe_starting_at(sf_start)[bit] ? -1 : 1;
    EXPECT_EQ(symbol, expected) << "bit " << k << " at SV tow " << t_sv.tow_s;
    flips += previous != 0 && symbol != previous;
    previous = symbol;
    ++checked;
  }
  EXPECT_GT(checked, 60);
  EXPECT_GT(flips, 10);  // real data, not a constant
}

TEST(IfSynthesiser, RejectsInvalidOptions) {
  auto o = base_options(2e6);
  o.real_output = true;
  o.if_hz = 0.0;
  EXPECT_NE(io::why_invalid(o), "");
  EXPECT_THROW(IfSynthesiser(o, {}, static_receiver()), std::invalid_argument);
  o = base_options(2e6);
  o.if_hz = 1.5e6;
  EXPECT_NE(io::why_invalid(o), "");
  o = base_options(2e6);
  o.cn0_dbhz_by_prn[40] = 45;
  EXPECT_NE(io::why_invalid(o), "");
  auto eph = walker_constellation(kStart);
  eph.push_back(eph.front());
  EXPECT_THROW(IfSynthesiser(base_options(2e6), eph, static_receiver()), std::invalid_argument);
}

}  // namespace
}  // namespace ultratrack::signals

namespace ultratrack::signals {
namespace {

// Two antennas at one point, noise and data off, one satellite: antenna 1's signal divided by antenna 0's is
// exp(-j 2 pi (line bias + slips + extra noise)) (RINEX sense: the synthesised phase falls as the path grows),
// and zero while blocked or faded.
struct ImpairedPair {
  std::vector<std::complex<float>> a0, a1;
  double fs = 0.5e6;
  ImpairedPair(SynthesiserOptions o, double seconds) {
    o.sample_rate_hz = fs;
    o.noise = false;
    o.nav_data = false;
    o.output_rms = 1.0;
    o.ionosphere = false;
    o.troposphere = false;
    const Eigen::Vector3d r0 = test_support::ecef_from_llh(35.274016, 137.013759, 100.0);
    auto eph = test_support::walker_constellation(kStart);
    SynthesiserOptions plain = o;
    plain.antenna_impairments.clear();
    plain.cycle_slips.clear();
    plain.blockages.clear();
    IfSynthesiser probe(plain, eph, static_receiver());
    const int prn = probe.visible_satellites(0).front().prn;
    for (auto& s : o.cycle_slips) s.prn = prn;
    IfSynthesiser synth(o, {eph[prn - 1]}, std::make_shared<StaticMotion>(std::vector<Eigen::Vector3d>{r0, r0}));
    const auto n = static_cast<std::size_t>(seconds * fs);
    a0.resize(n);
    a1.resize(n);
    std::vector<std::span<std::complex<float>>> spans{a0, a1};
    synth.generate(spans);
  }
  // Phase of antenna 1 against antenna 0 at sample i, cycles (RINEX sense), or NaN when antenna 1 is silent.
  double phase(std::size_t i) const {
    if (std::abs(a1[i]) < 1e-6f) return NAN;
    return -std::arg(std::complex<double>(a1[i]) * std::conj(std::complex<double>(a0[i]))) / (2 * std::numbers::pi);
  }
};

double wrap_cycles(double x) { return x - std::round(x); }

TEST(IfSynthesiser, LineBiasSlipAndBlockageOnOneAntenna) {
  auto o = base_options(0.5e6);
  o.antenna_impairments = {{}, {0.3, 0.0}};
  o.cycle_slips = {{1, 1, 0.0505, 2.25, 0.01}};  // prn set to the satellite by ImpairedPair
  o.blockages = {{1, 0.0205, 0.009}};
  const ImpairedPair p(o, 0.1);
  const double fs = p.fs;
  auto at = [&](double t) { return static_cast<std::size_t>(t * fs); };
  for (double t = 0.001; t < 0.02; t += 0.0007) EXPECT_NEAR(wrap_cycles(p.phase(at(t)) - 0.3), 0.0, 3e-4) << t;
  // 4096-entry carrier table: +-1.2e-4 cycles per antenna. Blockage [0.0205, 0.0295) resolved to 1 ms blocks: silent
  // from 0.021 to 0.029, present again from 0.030.
  for (double t = 0.0212; t < 0.0289; t += 0.0003) EXPECT_TRUE(std::isnan(p.phase(at(t)))) << t;
  for (double t = 0.0302; t < 0.05; t += 0.0007) EXPECT_NEAR(wrap_cycles(p.phase(at(t)) - 0.3), 0.0, 3e-4) << t;
  // The slip: faded for 10 ms, then stepped by 2.25 cycles (only the quarter cycle is visible).
  for (double t = 0.0512; t < 0.0599; t += 0.0003) EXPECT_TRUE(std::isnan(p.phase(at(t)))) << t;
  for (double t = 0.0612; t < 0.1; t += 0.0007) EXPECT_NEAR(wrap_cycles(p.phase(at(t)) - 0.55), 0.0, 3e-4) << t;
  // Antenna 0 is untouched throughout.
  for (double t = 0.0; t < 0.1; t += 0.0011) EXPECT_GT(std::abs(p.a0[at(t)]), 0.1f);
}

TEST(IfSynthesiser, ExtraPhaseNoiseHasTheConfiguredSigma) {
  // 3 mm on antenna 1 only: its phase against antenna 0 scatters by 3 mm / 19 cm = 0.0158 cycles around the
  // line bias. 20 s against a 0.1 s correlation time: ~100 independent values, so the sample sigma is within
  // ~7 % (1 sigma); 25 % tolerance.
  auto o = base_options(0.5e6);
  o.antenna_impairments = {{}, {0.1, 0.003}};
  const ImpairedPair p(o, 20.0);
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (std::size_t i = 250; i < p.a0.size(); i += 500) {  // every 1 ms, mid-node
    const double d = wrap_cycles(p.phase(i) - 0.1);
    sum += d;
    sum_sq += d * d;
    ++n;
  }
  const double mean = sum / n, sigma = std::sqrt(sum_sq / n - mean * mean);
  const double expected = 0.003 / kL1Wavelength_m;
  EXPECT_NEAR(sigma, expected, 0.25 * expected);
  EXPECT_NEAR(mean, 0.0, 0.005);  // 3 sigma of the mean of ~100 independent values
  std::printf("extra phase noise: sigma %.5f cycles (configured %.5f), mean %.5f\n", sigma, expected, mean);
}

TEST(IfSynthesiser, RejectsImpairmentsOfMissingAntennas) {
  auto o = base_options(0.5e6);
  o.blockages = {{1, 0.0, 1.0}};
  auto eph = test_support::walker_constellation(kStart);
  EXPECT_THROW(IfSynthesiser(o, eph, static_receiver()), std::invalid_argument);
  o.blockages = {{0, 0.0, 0.0}};
  EXPECT_FALSE(io::why_invalid(o).empty());
}

}  // namespace
}  // namespace ultratrack::signals

// C/N0 steps (issue 7's tracking threshold: strong for acquisition and sync, then weak).
namespace ultratrack::signals {
namespace {

// One satellite at 48 dB-Hz, stepped to 41 dB-Hz at 0.25 s and back up to 45 dB-Hz (that PRN listed) at 0.5 s:
// the independent brute-force acquisition's C/N0 (1 ms prompt power against the off-peak noise floor, 200 ms)
// on each 250 ms window reads the level of that window. Its statistical error: the mean of 200 1 ms prompt
// powers scatters by sqrt(2 / SNR + 1 / SNR^2) / sqrt(200) relative (SNR = C/N0 x 1 ms: 2.9 % at 41 dB-Hz, 1.3 %
// at 48), the noise floor from 8 x 200 off-peak values by 1 / sqrt(1600) = 2.5 %: 0.12-0.17 dB (1 sigma) on the
// ratio; 0.6 dB is 3.5-5 sigma. (This seed reads 44.56 dB-Hz in window 2 of an unstepped 45 dB-Hz file too.)
TEST(IfSynthesiser, Cn0StepsChangeTheMeasuredCn0WithinNoise) {
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(base_options(2.048e6), eph, static_receiver());
  const int prn = probe.visible_satellites(0)[1].prn;
  auto o = base_options(2.048e6);
  o.default_cn0_dbhz = 48.0;
  o.cn0_steps = {{0, 0.25, 41.0, {}}, {0, 0.5, 45.0, {prn}}};
  IfSynthesiser synth(o, {eph[prn - 1]}, static_receiver());
  EXPECT_EQ(synth.visible_satellites(0).front().cn0_dbhz, 48.0);
  EXPECT_EQ(synth.visible_satellites(512000).front().cn0_dbhz, 41.0);
  EXPECT_EQ(synth.cn0_dbhz(prn, 0, 1024000 - 1), 41.0);
  EXPECT_EQ(synth.cn0_dbhz(prn, 0, 1024000), 45.0);
  const auto x = via_file(synthesise(synth, 2048 * 750), SampleFormat::i8);
  const double expected[] = {48.0, 41.0, 45.0};
  for (int w = 0; w < 3; ++w) {
    const std::vector<std::complex<float>> window(x.begin() + w * 512000, x.begin() + (w + 1) * 512000);
    const auto r = BruteForceAcquisition(window, o.sample_rate_hz).acquire(prn, 200);
    ASSERT_TRUE(r.found) << w;
    EXPECT_NEAR(r.cn0_dbhz, expected[w], 0.6) << "window " << w;
    std::printf("C/N0 step: window %d measured %.2f dB-Hz for %.1f\n", w, r.cn0_dbhz, expected[w]);
  }
  // The noise floor is the same before and after the step (the gain is one for the run): the variance of the
  // samples, signal included, differs only by the signal's share, (C/N0) / fs = 3e-2 at 48 dB-Hz.
  const std::vector<std::complex<float>> before(x.begin(), x.begin() + 512000),
      after(x.begin() + 512000, x.begin() + 1024000);
  const double c48 = std::pow(10.0, 4.8) / o.sample_rate_hz, c41 = std::pow(10.0, 4.1) / o.sample_rate_hz;
  const double ratio =
      (variance(before, false) + variance(before, true)) / (variance(after, false) + variance(after, true));
  // Sample variance of 512000 complex samples: relative sigma 1 / sqrt(512000) = 0.0014 per window; 4 sigma on the
  // ratio.
  EXPECT_NEAR(ratio, (1.0 + c48) / (1.0 + c41), 4 * std::sqrt(2.0 / 512000));
}

// Noise and data off, two antennas at one point and two satellites: the step acts on antenna 1 and on the listed
// PRN only, from exactly the first sample at or after start_s (inside a 1 ms block and inside a generate() call),
// and the envelope of the stepped satellite (constant for a BPSK code times a unit carrier) changes by exactly
// 10^(dB/20) there: a1 - a0 = (10^(-6/20) - 1) x that satellite's signal.
TEST(IfSynthesiser, Cn0StepIsSampleExactOnItsAntennaAndSatellitesOnly) {
  auto eph = walker_constellation(kStart);
  IfSynthesiser probe(base_options(1.0e6), eph, static_receiver());
  const auto views = probe.visible_satellites(0);
  const int stepped = views[0].prn, other = views[1].prn;
  auto o = base_options(1.0e6);
  o.noise = false;
  o.default_cn0_dbhz = 45.0;
  o.cn0_steps = {{1, 0.0123456, 39.0, {stepped}}};
  const std::int64_t first = cn0_step_first_sample(o.cn0_steps[0], o.sample_rate_hz);
  ASSERT_EQ(first, 12346);  // 12345.6 samples: the next whole sample
  const Eigen::Vector3d r0 = ecef_from_llh(35.274016, 137.013759, 100.0);
  IfSynthesiser synth(o, {eph[stepped - 1], eph[other - 1]},
                      std::make_shared<StaticMotion>(std::vector<Eigen::Vector3d>{r0, r0}));
  const std::size_t n = 30000;
  std::vector<std::complex<float>> a0(n), a1(n);
  for (std::size_t done = 0; done < n;) {  // calls of 777 samples: the step falls inside one
    const std::size_t c = std::min<std::size_t>(777, n - done);
    std::vector<std::span<std::complex<float>>> spans{std::span(a0.data() + done, c), std::span(a1.data() + done, c)};
    synth.generate(spans);
    done += c;
  }
  // Envelope of one satellite at 45 dB-Hz: gain x sqrt(2 C/N0 / fs) (documented amplitude).
  const double envelope = synth.gain() * std::sqrt(2.0 * std::pow(10.0, 4.5) / o.sample_rate_hz);
  const double drop = (1.0 - std::pow(10.0, -6.0 / 20.0)) * envelope;
  EXPECT_NEAR(synth.amplitude(stepped), envelope, 1e-9 * envelope);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::abs(std::complex<double>(a1[i]) - std::complex<double>(a0[i]));
    if (static_cast<std::int64_t>(i) < first) {
      ASSERT_LT(d, 1e-6 * envelope) << "sample " << i << " before the step";
    } else {
      ASSERT_NEAR(d, drop, 1e-4 * envelope) << "sample " << i << " after the step";  // float samples, 4096-entry table
    }
  }
  EXPECT_EQ(synth.cn0_dbhz(stepped, 1, first), 39.0);
  EXPECT_EQ(synth.cn0_dbhz(stepped, 1, first - 1), 45.0);
  EXPECT_EQ(synth.cn0_dbhz(stepped, 0, first), 45.0);
  EXPECT_EQ(synth.cn0_dbhz(other, 1, first), 45.0);
}

// A step up: the gain is set for each satellite's strongest level, so the output RMS stays at or below
// output_rms over the run (no extra clipping), and a step to a level does what that level as a start does.
TEST(IfSynthesiser, Cn0StepUpSetsTheGainForTheStrongestLevel) {
  auto eph = walker_constellation(kStart);
  auto o = base_options(2.0e6);
  o.default_cn0_dbhz = 40.0;
  o.cn0_steps = {{0, 0.001, 65.0, {}}};
  IfSynthesiser stepped(o, eph, static_receiver());
  auto strong = base_options(2.0e6);
  strong.default_cn0_dbhz = 65.0;
  IfSynthesiser reference(strong, eph, static_receiver());
  EXPECT_NEAR(stepped.gain(), reference.gain(), 1e-12 * reference.gain());
  const auto x = synthesise(stepped, 200000);
  const std::vector<std::complex<float>> after(x.begin() + 2000, x.end());
  EXPECT_NEAR((variance(after, false) + variance(after, true)) / 2 / (o.output_rms * o.output_rms), 1.0, 0.01);
  o.cn0_steps = {{0, 0.0, 81.0, {}}};
  EXPECT_FALSE(io::why_invalid(o).empty());
  o.cn0_steps = {{0, 0.0, 30.0, {33}}};
  EXPECT_FALSE(io::why_invalid(o).empty());
  o.cn0_steps = {{1, 0.0, 30.0, {}}};
  EXPECT_THROW(IfSynthesiser(o, eph, static_receiver()), std::invalid_argument);
}

}  // namespace
}  // namespace ultratrack::signals
