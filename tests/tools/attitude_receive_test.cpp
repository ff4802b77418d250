// SPDX-License-Identifier: GPL-3.0-or-later
// The multi-antenna receive path end to end on the synthesiser's signal, without the attitude solver: a static
// 3-antenna receiver (ENU offsets, so the geometry is exact and independent of any attitude code), 45 dB-Hz, 3 mm
// of extra phase noise per antenna, line biases, one injected cycle slip and a short blockage. Checked against
// the construction: phase_k - phase_0 = -(b_k . los) / lambda + line bias_k + integer, the integer constant while
// no slip flag is raised, and the flags at the injected events (antenna_events.csv's truth).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include "config/scenario_toml.hpp"
#include "io/units.hpp"
#include "receiver/multi_sample_source.hpp"
#include "receiver/receiver_engine.hpp"
#include "signals/gps_constants.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/input_error.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario_models.hpp"
#include "simulation_run.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

struct Collector final : receiver::ReceiverObserver {
  std::vector<receiver::AntennaPhaseEpoch> epochs;
  void on_antenna_phases(const receiver::AntennaPhaseEpoch& e) override { epochs.push_back(e); }
};

sim::Scenario attitude_scenario() {
  sim::Scenario s;
  s.sample_rate_hz = 2.6e6;
  s.format = signals::SampleFormat::i8;
  s.duration_s = 15.0;
  s.cn0_dbhz = 45.0;
  s.seed = 5;
  s.gps_week = 2190;
  s.tow_s = 518396.0;  // the first time tag at ~10 s, when the subframe 518400-518406 completes
  s.constellation = "nominal";
  s.ionosphere = false;
  // Master, 1 m at azimuth 35 deg, 1.025 m at azimuth 125 deg (the seed array turned by 35 deg of yaw).
  s.antenna_offsets_enu_m = {{0.0, 0.0, 0.0},
                             {std::sin(35 * io::kRadPerDeg), std::cos(35 * io::kRadPerDeg), 0.0},
                             {1.025 * std::sin(125 * io::kRadPerDeg), 1.025 * std::cos(125 * io::kRadPerDeg), 0.0}};
  s.antenna_impairments = {{0.0, 0.003}, {0.23, 0.003}, {-0.41, 0.003}};
  return s;
}

// The engine over the simulated files with `threads` threads: every antenna-phase epoch and tracking record.
Collector receive(const sim::Scenario& s, const std::vector<fs::path>& files, const sim::NavigationSource& nav,
                  int threads) {
  receiver::ReceiverOptions options;
  options.fs_hz = s.sample_rate_hz;
  options.num_antennas = 3;
  options.reference_week = s.gps_week;
  options.reference_week_is_signal_week = true;
  options.pvt.ionosphere = false;
  options.threads = threads;
  Collector collector;
  receiver::ReceiverEngine engine(options, collector);
  EXPECT_EQ(engine.threads(), threads);
  engine.add_navigation(nav.ephemerides, nav.klobuchar, nav.utc);
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = s.sample_rate_hz;
  receiver::MultiSampleSource source(files, s.format, source_options);
  const std::size_t block = 130000;
  std::vector<std::vector<std::complex<float>>> buf(3, std::vector<std::complex<float>>(block));
  std::vector<std::span<std::complex<float>>> out(3);
  std::vector<std::span<const std::complex<float>>> in(3);
  for (;;) {
    for (int a = 0; a < 3; ++a) out[a] = std::span(buf[a]);
    const auto got = source.read(out);
    if (got.count == 0) break;
    for (int a = 0; a < 3; ++a) in[a] = std::span<const std::complex<float>>(buf[a].data(), got.count);
    engine.process(std::span<const std::span<const std::complex<float>>>(in), got.first_sample);
  }
  return collector;
}

bool same_epoch(const receiver::AntennaPhaseEpoch& a, const receiver::AntennaPhaseEpoch& b) {
  if (a.sample_index != b.sample_index || a.receive_time.week != b.receive_time.week ||
      a.receive_time.tow_s != b.receive_time.tow_s || a.master_position_e != b.master_position_e ||
      a.satellites.size() != b.satellites.size())
    return false;
  for (std::size_t i = 0; i < a.satellites.size(); ++i) {
    const auto &x = a.satellites[i], &y = b.satellites[i];
    if (x.prn != y.prn || x.los_e != y.los_e || x.elevation_rad != y.elevation_rad ||
        x.num_antennas != y.num_antennas || x.carrier_phase_cycles != y.carrier_phase_cycles || x.slip != y.slip ||
        x.usable != y.usable)
      return false;
    for (int k = 0; k < x.num_antennas; ++k)  // NaN C/N0 (no estimate yet) equals NaN here
      if (!(x.cn0_dbhz[k] == y.cn0_dbhz[k] || (std::isnan(x.cn0_dbhz[k]) && std::isnan(y.cn0_dbhz[k])))) return false;
  }
  return true;
}

}  // namespace

TEST(AttitudeReceive, BetweenAntennaPhasesMatchTheGeometryAndFlagTheEvents) {
  sim::Scenario s = attitude_scenario();
  const sim::NavigationSource nav = sim::load_navigation(s);
  // The slip goes on the highest satellite (sure to be tracked).
  int slip_prn = 0;
  {
    signals::IfSynthesiser probe(sim::synthesiser_options(s, nav), nav.ephemerides, sim::make_motion(s));
    double best = -1.0;
    for (const auto& v : probe.visible_satellites(0))
      if (v.elevation_rad > best) best = v.elevation_rad, slip_prn = v.prn;
  }
  ASSERT_GT(slip_prn, 0);
  s.cycle_slips = {{1, slip_prn, 12.0, 3.0, 0.1}};
  s.blockages = {{2, 13.0, 0.5}};
  const fs::path dir = test::scratch_dir() / "attitude_receive";
  const sim::SimulationResult sim = tools::run_simulation(s, dir);
  ASSERT_EQ(sim.sample_files.size(), 3u);
  ASSERT_TRUE(fs::exists(dir / "antenna_events.csv"));

  const Collector collector = receive(s, sim.sample_files, nav, 1);
  ASSERT_GT(collector.epochs.size(), 35u)
      << "antenna phases from at least 2 s of the run; first at "
      << (collector.epochs.empty() ? -1.0 : collector.epochs.front().receive_time.tow_s);

  // Baselines in ECEF from the scenario's ENU offsets (exact: a static receiver).
  const auto motion = sim::make_motion(s);
  const Eigen::Vector3d r0 = motion->antenna_state(0, 0.0).r_e_m;
  std::array<Eigen::Vector3d, 3> b;
  for (int k = 0; k < 3; ++k) b[k] = motion->antenna_state(k, 0.0).r_e_m - r0;

  std::map<std::pair<int, int>, double> integer;  // (prn, antenna) -> the integer of the current arc
  double sum_sq = 0.0, worst = 0.0;
  int count = 0, arcs_broken_without_flag = 0;
  bool slip_seen = false, block_seen = false, block_recovered = false;
  int false_flags = 0;
  const double t0 = 518396.0;
  for (const auto& e : collector.epochs) {
    const double t = e.receive_time.tow_s - t0;  // receiver time since the start, within ~1 ms
    EXPECT_LT((e.master_position_e - r0).norm(), 30.0);
    for (const auto& o : e.satellites) {
      ASSERT_EQ(o.num_antennas, 3);
      for (int k = 1; k < 3; ++k) {
        const auto key = std::make_pair(o.prn, k);
        const bool in_block = k == 2 && t >= 13.0 && t < 13.5;
        const bool in_fade = k == 1 && o.prn == slip_prn && t >= 12.0 && t < 12.1;
        if (in_block || in_fade) {
          EXPECT_FALSE(o.usable[k]) << "t " << t << " prn " << o.prn << " antenna " << k;
          if (in_block) block_seen = true;
        }
        if (!o.usable[k]) continue;
        const double sd = o.carrier_phase_cycles[k] - o.carrier_phase_cycles[0];
        const double geometric = -b[k].dot(o.los_e) / signals::kL1Wavelength_m;
        const double r = sd - geometric - s.antenna_impairments[k].line_bias_cycles;
        const double n = std::round(r);
        const double frac = r - n;
        sum_sq += frac * frac;
        worst = std::max(worst, std::abs(frac));
        ++count;
        if (o.slip[k]) {
          // Flags inside an arc (not its first epoch) at the events.
          const bool inside_arc = integer.count(key) > 0;
          if (inside_arc && k == 1 && o.prn == slip_prn && t >= 12.0 && t < 12.6)
            slip_seen = true;
          else if (inside_arc && k == 2 && t >= 13.5 && t < 13.8)
            block_recovered = true;
          else if (integer.count(key))
            ++false_flags;  // a flag that no event explains (the first of an arc is fine)
          integer[key] = n;
        } else if (integer.count(key) && integer[key] != n) {
          ++arcs_broken_without_flag;
          integer[key] = n;
        } else {
          integer[key] = n;
        }
      }
    }
  }
  ASSERT_GT(count, 200);
  const double rms = std::sqrt(sum_sq / count);
  std::printf("[ figures  ] %d between-antenna phases, %zu epochs: fractional residual rms %.4f, worst %.4f cycles\n",
              count, collector.epochs.size(), rms, worst);
  // Between-antenna noise: 3 mm per antenna -> 4.2 mm = 0.022 cycles, plus 0.006 cycles thermal (45 dB-Hz, 20 ms):
  // 0.023 cycles. RMS within 50 % of it; the worst of ~700 values below 6.5 sigma.
  EXPECT_LT(rms, 0.035) << "count " << count;
  EXPECT_GT(rms, 0.012);
  EXPECT_LT(worst, 0.15);
  EXPECT_EQ(arcs_broken_without_flag, 0);
  EXPECT_TRUE(slip_seen) << "the injected slip on PRN " << slip_prn << " was not flagged";
  EXPECT_TRUE(block_seen);
  EXPECT_TRUE(block_recovered) << "no slip flag within 0.3 s of the end of the blockage";
  EXPECT_EQ(false_flags, 0);
}

// The multi-antenna path gives the same bits with 1, 2 and 3 threads: every antenna is correlated inside its
// channel's job, and everything shared is done in channel order on the caller's thread.
TEST(AttitudeReceive, AntennaPhasesAreIdenticalForAnyNumberOfThreads) {
  sim::Scenario s = attitude_scenario();
  s.duration_s = 12.0;
  const sim::NavigationSource nav = sim::load_navigation(s);
  {
    signals::IfSynthesiser probe(sim::synthesiser_options(s, nav), nav.ephemerides, sim::make_motion(s));
    s.cycle_slips = {{1, probe.visible_satellites(0).front().prn, 11.0, 3.0, 0.1}};
  }
  s.blockages = {{2, 11.3, 0.3}};
  const fs::path dir = test::scratch_dir() / "attitude_receive_threads";
  const sim::SimulationResult sim = tools::run_simulation(s, dir);
  const Collector one = receive(s, sim.sample_files, nav, 1);
  ASSERT_GT(one.epochs.size(), 10u);
  for (int threads = 2; threads <= 3; ++threads) {
    const Collector other = receive(s, sim.sample_files, nav, threads);
    ASSERT_EQ(other.epochs.size(), one.epochs.size()) << threads << " threads";
    for (std::size_t i = 0; i < one.epochs.size(); ++i)
      ASSERT_TRUE(same_epoch(one.epochs[i], other.epochs[i]))
          << "epoch " << i << " differs with " << threads << " threads";
  }
}

TEST(AttitudeReceive, FilesOfDifferentLengthsAreAnInputError) {
  const fs::path dir = test::scratch_dir() / "attitude_lengths";
  fs::create_directories(dir);
  {
    std::ofstream(dir / "a.bin", std::ios::binary) << std::string(2000, '\0');
    std::ofstream(dir / "b.bin", std::ios::binary) << std::string(1998, '\0');
  }
  receiver::SampleSourceOptions o;
  o.fs_hz = 2e6;
  try {
    receiver::MultiSampleSource source({dir / "a.bin", dir / "b.bin"}, signals::SampleFormat::i8, o);
    FAIL() << "no error";
  } catch (const signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sample-synchronously"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("b.bin"), std::string::npos) << e.what();
  }
}
