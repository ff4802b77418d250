// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/if_synthesiser.hpp"

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "io/why_invalid.hpp"
#include "signals/atmosphere.hpp"
#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"
#include "signals/satellite_state.hpp"
#include "signals/synth_kernels.hpp"

namespace ultratrack::signals {
namespace {

constexpr double kTwentyMs_s = 0.02;
constexpr double kChipsPerBit = kCaChipRate_hz * kTwentyMs_s;  // 20460
constexpr double kNodeInterval_s = 1e-3;                       // exact nodes every millisecond
constexpr double kVisibilityInterval_s = 1.0;                  // elevation mask re-evaluated every second
constexpr double kDopplerHalfStep_s = 0.5e-3;

double floor_mod(double x, double m) { return x - m * std::floor(x / m); }

// Receiver-side geometry of one antenna at one node.
struct RxGeo {
  double tau_s = 0.0;  // receiver time since sample 0
  double t_r_s = 0.0;  // true GPS time since start
  ReceiverClockState clock;
  AntennaState state;
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Matrix3d C_enu_e = Eigen::Matrix3d::Identity();  // ECEF -> local east/north/up
};

struct Solution {
  SignalTiming timing;
  double travel_s = 0.0;        // geometric light time
  double d_code_s = 0.0;        // atmospheric group delay
  double code_chips = 0.0;      // continuous: chips since a 20 ms boundary before the start
  double carrier_cycles = 0.0;  // continuous
};

struct Node {
  std::int64_t sample = std::numeric_limits<std::int64_t>::min();
  double code_chips = 0.0;
  double carrier_cycles = 0.0;
};

}  // namespace

struct IfSynthesiser::Impl {
  struct Sat {
    Ephemeris eph;
    double cn0_dbhz = 45.0;
    double amplitude = 0.0;  // internal units (noise sigma = 1)
    bool active = false;
    std::array<float, kCaCodeLength_chips> chip_amplitude{};  // +-gain*A per chip
  };
  struct Level {  // a C/N0 step of one track
    std::int64_t first_sample = 0;
    double cn0_dbhz = 0.0;
    float scale = 1.0f;  // amplitude against the satellite's base amplitude
  };
  struct Track {  // one satellite on one antenna
    Node n0, n1;
    std::vector<Level> levels;  // in sample order
    double travel_guess_s = 0.075;
    double d_guess_s = 0.0;
    std::unique_ptr<LnavTransmitter> lnav;
    // Extra phase noise (Gauss-Markov state, metres) and its generator.
    double noise_m = 0.0;
    bool noise_started = false;
    std::mt19937_64 rng;
    // Held parameters (parameter_update_s > 1 ms): code and carrier advance per block, the held code and
    // carrier at the next block's start (before the clock noise), and the carrier offset (line bias, slips,
    // extra noise) at the last update.
    bool held = false;
    double code_step_chips = 0.0;
    double carrier_step_cycles = 0.0;
    double held_code_chips = 0.0;
    double held_carrier_cycles = 0.0;
    double offset_cycles = 0.0;
  };

  const SynthesiserOptions& opt;
  const ReceiverMotion& motion;
  ReceiverClock clock;
  std::vector<Sat> sats;
  std::vector<Track> tracks;  // antenna-major: tracks[a * sats.size() + k]
  std::vector<synth::GaussianNoise> noise;
  std::vector<std::int64_t> step_samples;  // every C/N0 step's first sample, sorted, unique
  std::int64_t block_samples = 1;
  std::int64_t update_blocks = 1;  // blocks per parameter update (1: exact nodes at every block)
  std::int64_t visibility_blocks = 1000;
  std::int64_t current_block = -1;
  double frac20_s = 0.0;          // start.tow_s modulo 20 ms: aligns code epochs and data bits with GPS time
  std::vector<RxGeo> geo0, geo1;  // per antenna at the current block's two nodes

  Impl(const SynthesiserOptions& o, const ReceiverMotion& m) : opt(o), motion(m), clock(o.clock, o.seed) {}

  double tau_of(std::int64_t sample) const { return static_cast<double>(sample) / opt.sample_rate_hz; }

  // noisy_clock false: the clock's deterministic part only (bias + drift tau), for held parameters.
  RxGeo rx_geo(int antenna, double tau_s, bool noisy_clock = true) {
    RxGeo g;
    g.tau_s = tau_s;
    g.clock = noisy_clock ? clock.at(tau_s)
                          : ReceiverClockState{opt.clock.bias_s + opt.clock.drift_sps * tau_s, opt.clock.drift_sps};
    g.t_r_s = tau_s - (g.clock.bias_s - opt.clock.bias_s);
    g.state = motion.antenna_state(antenna, g.t_r_s);
    double lat_deg = 0, lon_deg = 0, h = 0;
    GeographicLib::Geocentric::WGS84().Reverse(g.state.r_e_m.x(), g.state.r_e_m.y(), g.state.r_e_m.z(), lat_deg,
                                               lon_deg, h);
    g.lat_rad = lat_deg * M_PI / 180.0;
    g.lon_rad = lon_deg * M_PI / 180.0;
    g.height_m = h;
    const double sl = std::sin(g.lat_rad), cl = std::cos(g.lat_rad);
    const double so = std::sin(g.lon_rad), co = std::cos(g.lon_rad);
    g.C_enu_e << -so, co, 0.0, -sl * co, -sl * so, cl, cl * co, cl * so, sl;
    return g;
  }

  // The exact signal parameters: iterated light time with Sagnac, atmosphere, SV clock.
  Solution solve(const Sat& sat, const RxGeo& rx, double travel_guess_s, double d_guess_s) const {
    const Eigen::Vector3d& r_rx = rx.state.r_e_m;
    double travel = travel_guess_s;
    double d = d_guess_s;
    double iono_s = 0.0, tropo_m = 0.0, el = 0.0, az = 0.0;
    Eigen::Vector3d r_sat = Eigen::Vector3d::Zero();
    for (int outer = 0; outer < 4; ++outer) {
      for (int it = 0; it < 10; ++it) {
        const double flight = travel + d;
        const SatelliteState st = satellite_state(sat.eph, add_seconds(opt.start, rx.t_r_s - flight));
        r_sat = rotate_to_receive_frame(st.r_e_m, flight);
        const double next = (r_sat - r_rx).norm() / kSpeedOfLight_mps;
        const bool converged = std::abs(next - travel) < 1e-15;
        travel = next;
        if (converged) break;
      }
      const Eigen::Vector3d los_enu = rx.C_enu_e * (r_sat - r_rx).normalized();
      el = std::asin(std::clamp(los_enu.z(), -1.0, 1.0));
      az = std::atan2(los_enu.x(), los_enu.y());
      if (az < 0) az += 2 * M_PI;
      iono_s = opt.ionosphere ? klobuchar_delay_s(opt.klobuchar, rx.lat_rad, rx.lon_rad, az, el,
                                                  add_seconds(opt.start, rx.t_r_s).tow_s)
                              : 0.0;
      // The troposphere model is for satellites above the horizon; below it the signal is masked anyway.
      tropo_m = opt.troposphere ? troposphere_delay_m(rx.lat_rad, rx.height_m, std::max(el, 2.0 * M_PI / 180.0)) : 0.0;
      const double next_d = iono_s + tropo_m / kSpeedOfLight_mps;
      const bool converged = std::abs(next_d - d) < 1e-15;
      d = next_d;
      if (converged) break;
    }
    const double t_tx_code = rx.t_r_s - travel - d;
    const double dt_sv = l1_ca_clock_correction_s(sat.eph, add_seconds(opt.start, t_tx_code));
    const double t_sv_code = t_tx_code + dt_sv;
    const double t_sv_carrier = rx.t_r_s - travel - (tropo_m / kSpeedOfLight_mps - iono_s) + dt_sv;
    const double rx_clock = opt.clock.bias_s + rx.tau_s;

    Solution s;
    s.travel_s = travel;
    s.d_code_s = d;
    s.code_chips = (frac20_s + t_sv_code) * kCaChipRate_hz;
    s.carrier_cycles = kL1Frequency_hz * (t_sv_carrier - rx_clock) + opt.if_hz * rx.tau_s;
    SignalTiming& t = s.timing;
    t.receive_time_s = rx.t_r_s;
    t.rx_clock_s = rx_clock;
    t.code_sv_time_s = t_sv_code;
    t.carrier_sv_time_s = t_sv_carrier;
    t.pseudorange_m = kSpeedOfLight_mps * (rx_clock - t_sv_code);
    t.geometric_range_m = travel * kSpeedOfLight_mps;
    t.iono_delay_m = iono_s * kSpeedOfLight_mps;
    t.tropo_delay_m = tropo_m;
    t.sv_clock_s = dt_sv;
    t.rx_clock_bias_s = rx.clock.bias_s;
    t.code_phase_chips = floor_mod(s.code_chips, kCaCodeLength_chips);
    t.carrier_phase_cycles = s.carrier_cycles;
    t.elevation_rad = el;
    t.azimuth_rad = az;
    return s;
  }

  // The exact node without the carrier offsets.
  Node geometric_node(std::size_t k, int antenna, const RxGeo& rx, std::int64_t sample) {
    Track& tr = tracks[static_cast<std::size_t>(antenna) * sats.size() + k];
    const Solution s = solve(sats[k], rx, tr.travel_guess_s, tr.d_guess_s);
    tr.travel_guess_s = s.travel_s;
    tr.d_guess_s = s.d_code_s;
    return {sample, s.code_chips, s.carrier_cycles};
  }

  Node node_at(std::size_t k, int antenna, const RxGeo& rx, std::int64_t sample) {
    Track& tr = tracks[static_cast<std::size_t>(antenna) * sats.size() + k];
    Node n = geometric_node(k, antenna, rx, sample);
    n.carrier_cycles -= carrier_offset_cycles(tr, sats[k].eph.prn, antenna, sample, kNodeInterval_s);
    return n;
  }

  // Line bias + slips + extra noise of a track at a node, cycles, RINEX sense (the synthesised phase falls
  // with range, so the caller subtracts it); dt_s since the track's previous node (the noise's step).
  double carrier_offset_cycles(Track& tr, int prn, int antenna, std::int64_t sample, double dt_s) {
    double cycles = 0.0;
    if (antenna < static_cast<int>(opt.antenna_impairments.size())) {
      const AntennaImpairment& imp = opt.antenna_impairments[static_cast<std::size_t>(antenna)];
      cycles += imp.line_bias_cycles;
      if (imp.phase_noise_m > 0.0) {
        std::normal_distribution<double> gauss;
        if (!tr.noise_started) {
          tr.noise_m = imp.phase_noise_m * gauss(tr.rng);
          tr.noise_started = true;
        } else {
          const double phi = std::exp(-dt_s / opt.phase_noise_correlation_s);
          tr.noise_m = phi * tr.noise_m + std::sqrt(1.0 - phi * phi) * imp.phase_noise_m * gauss(tr.rng);
        }
        cycles += tr.noise_m / kL1Wavelength_m;
      }
    }
    const double tau = tau_of(sample);
    for (const CycleSlipEvent& e : opt.cycle_slips)
      if (e.antenna == antenna && e.prn == prn && tau >= e.time_s) cycles += e.cycles;
    return cycles;
  }

  // The C/N0 step in force on a track at a sample (nullptr: the satellite's base level).
  static const Level* level_at(const Track& tr, std::int64_t sample) {
    const Level* in_force = nullptr;
    for (const Level& l : tr.levels) {
      if (l.first_sample > sample) break;
      in_force = &l;
    }
    return in_force;
  }

  // Whether satellite prn's signal is absent at antenna a at receiver time tau (blockage or a slip's fade).
  bool absent(int prn, int antenna, double tau) const {
    for (const BlockageEvent& b : opt.blockages)
      if (b.antenna == antenna && tau >= b.start_s && tau < b.start_s + b.duration_s) return true;
    for (const CycleSlipEvent& e : opt.cycle_slips)
      if (e.antenna == antenna && e.prn == prn && tau >= e.time_s && tau < e.time_s + e.fade_s) return true;
    return false;
  }

  void update_visibility(std::int64_t sample) {
    const RxGeo rx = rx_geo(0, tau_of(sample));
    for (auto& sat : sats) sat.active = solve(sat, rx, 0.075, 0.0).timing.elevation_rad >= opt.elevation_mask_rad;
  }

  // Makes n0/n1 of every active track the exact nodes of block b (or the held ones).
  void enter_block(std::int64_t b) {
    if (b % visibility_blocks == 0 || current_block < 0) update_visibility(b * block_samples);
    current_block = b;
    if (update_blocks > 1) {
      enter_held_block(b);
      return;
    }
    const std::int64_t s0 = b * block_samples, s1 = s0 + block_samples;
    for (int a = 0; a < static_cast<int>(geo0.size()); ++a) {
      bool need0 = false;
      for (std::size_t k = 0; k < sats.size(); ++k) {
        Track& tr = tracks[static_cast<std::size_t>(a) * sats.size() + k];
        if (!sats[k].active) continue;
        if (tr.n1.sample == s0) tr.n0 = tr.n1;
        if (tr.n0.sample != s0) need0 = true;
      }
      if (need0) geo0[a] = rx_geo(a, tau_of(s0));
      geo1[a] = rx_geo(a, tau_of(s1));
      for (std::size_t k = 0; k < sats.size(); ++k) {
        if (!sats[k].active) continue;
        Track& tr = tracks[static_cast<std::size_t>(a) * sats.size() + k];
        if (tr.n0.sample != s0) tr.n0 = node_at(k, a, geo0[a], s0);
        tr.n1 = node_at(k, a, geo1[a], s1);
      }
    }
  }

  // Held parameters: at an update block (or a track's first) the exact nodes at its two ends give the code
  // and carrier advance per block, kept until the next update; the code restarts from its exact value there,
  // the carrier continues from where it was, stepping only by the change of its offsets (slips, line bias).
  // What is held is the generator's geometry on the clock's deterministic part: the oscillator's noise is the
  // front end's, so it stays on every block (as a time shift of the whole signal: -db chips and cycles at the
  // code and carrier rates, to 1e-5 of db, the Doppler's share).
  void enter_held_block(std::int64_t b) {
    const std::int64_t s0 = b * block_samples, s1 = s0 + block_samples;
    const bool update = b % update_blocks == 0;
    const auto clock_noise_s = [&](std::int64_t sample) {
      const double tau = tau_of(sample);
      return clock.at(tau).bias_s - (opt.clock.bias_s + opt.clock.drift_sps * tau);
    };
    const double db0 = clock_noise_s(s0), db1 = clock_noise_s(s1);
    for (int a = 0; a < static_cast<int>(geo0.size()); ++a) {
      bool geo_done = false;
      for (std::size_t k = 0; k < sats.size(); ++k) {
        Track& tr = tracks[static_cast<std::size_t>(a) * sats.size() + k];
        if (!sats[k].active) {
          tr.held = false;
          continue;
        }
        if (update || !tr.held) {
          if (!geo_done) {
            geo0[a] = rx_geo(a, tau_of(s0), false);
            geo1[a] = rx_geo(a, tau_of(s1), false);
            geo_done = true;
          }
          const Node e0 = geometric_node(k, a, geo0[a], s0);
          const Node e1 = geometric_node(k, a, geo1[a], s1);
          const double dt = tr.held ? static_cast<double>(update_blocks) * kNodeInterval_s : kNodeInterval_s;
          const double offset = carrier_offset_cycles(tr, sats[k].eph.prn, a, s0, dt);
          tr.held_carrier_cycles =
              tr.held ? tr.held_carrier_cycles - (offset - tr.offset_cycles) : e0.carrier_cycles - offset;
          tr.held_code_chips = e0.code_chips;
          tr.code_step_chips = e1.code_chips - e0.code_chips;
          tr.carrier_step_cycles = e1.carrier_cycles - e0.carrier_cycles;
          tr.offset_cycles = offset;
          tr.held = true;
        }
        tr.n0 = {s0, tr.held_code_chips - kCaChipRate_hz * db0, tr.held_carrier_cycles - kL1Frequency_hz * db0};
        tr.held_code_chips += tr.code_step_chips;
        tr.held_carrier_cycles += tr.carrier_step_cycles;
        tr.n1 = {s1, tr.held_code_chips - kCaChipRate_hz * db1, tr.held_carrier_cycles - kL1Frequency_hz * db1};
      }
    }
  }

  // Adds satellite k's signal on antenna a for samples [first, first + count) of the current block.
  // The caller splits segments at the C/N0 steps, so one amplitude scale holds for the whole segment.
  void add_satellite(std::size_t k, int a, std::int64_t first, std::complex<float>* out, std::size_t count) {
    Track& tr = tracks[static_cast<std::size_t>(a) * sats.size() + k];
    const Level* level = level_at(tr, first);
    const float scale = level ? level->scale : 1.0f;
    const double n_in_block = static_cast<double>(first - tr.n0.sample);
    const double code_rate = (tr.n1.code_chips - tr.n0.code_chips) / static_cast<double>(block_samples);
    const double carrier_rate = (tr.n1.carrier_cycles - tr.n0.carrier_cycles) / static_cast<double>(block_samples);
    double code = tr.n0.code_chips + n_in_block * code_rate;
    double carrier = tr.n0.carrier_cycles + n_in_block * carrier_rate;
    std::size_t done = 0;
    while (done < count) {
      // Split at data-bit boundaries (every 20460 chips of SV time): constant data sign per segment.
      std::size_t seg = count - done;
      const double bit_end = (std::floor(code / kChipsPerBit) + 1.0) * kChipsPerBit;
      const double to_boundary = std::ceil((bit_end - code) / code_rate);
      if (to_boundary < static_cast<double>(seg)) seg = static_cast<std::size_t>(std::max(1.0, to_boundary));
      float data = 1.0f;
      if (opt.nav_data) {
        const double mid_chips = code + 0.5 * static_cast<double>(seg - 1) * code_rate;
        const double t_sv = mid_chips / kCaChipRate_hz - frac20_s;
        data = static_cast<float>(tr.lnav->data_symbol_at(add_seconds(opt.start, t_sv)));
      }
      synth::add_code_carrier(out + done, seg, sats[k].chip_amplitude.data(), data * scale,
                              floor_mod(code, kCaCodeLength_chips), code_rate, carrier, carrier_rate, opt.real_output);
      done += seg;
      code += static_cast<double>(seg) * code_rate;
      carrier += static_cast<double>(seg) * carrier_rate;
    }
  }
};

bool SynthesiserOptions::IsValid(std::string* why) const {
  const SynthesiserOptions& o = *this;
  const std::string problem = [&]() -> std::string {
    if (!(o.sample_rate_hz >= 1e5 && o.sample_rate_hz <= 1e9)) return "sample rate must be between 100 kHz and 1 GHz";
    if (!(std::abs(o.if_hz) < 0.5 * o.sample_rate_hz)) return "|if_hz| must be below half the sample rate";
    if (o.real_output && !(o.if_hz > 0.0)) return "real sample formats need an IF above 0 Hz (if_hz > 0)";
    if (!(o.output_rms > 0.0)) return "output_rms must be positive";
    if (!(o.default_cn0_dbhz >= 0.0 && o.default_cn0_dbhz <= 80.0)) return "cn0_dbhz must be within 0..80 dB-Hz";
    for (const auto& [prn, cn0] : o.cn0_dbhz_by_prn) {
      if (prn < kMinPrn || prn > kMaxPrn) return "C/N0 override for PRN " + std::to_string(prn) + ": PRN must be 1..32";
      if (!(cn0 >= 0.0 && cn0 <= 80.0)) return "C/N0 of PRN " + std::to_string(prn) + " must be within 0..80 dB-Hz";
    }
    if (!(o.start.tow_s >= 0.0 && o.start.tow_s < kSecondsPerWeek) || o.start.week < 0)
      return "start time must have week >= 0 and 0 <= tow_s < 604800";
    if (!(o.elevation_mask_rad >= -M_PI / 2 && o.elevation_mask_rad <= M_PI / 2)) return "elevation mask out of range";
    if (!(o.clock.bias_noise_s_per_sqrt_s >= 0.0) || !(o.clock.drift_noise_sps_per_sqrt_s >= 0.0))
      return "clock noise densities must be >= 0";
    if (!(std::abs(o.clock.drift_sps) < 1e-3)) return "clock drift must be below 1e-3 s/s (300 km/s)";
    if (!std::isfinite(o.clock.bias_s) || std::abs(o.clock.bias_s) > 1.0) return "clock bias must be below 1 s";
    if (!(o.phase_noise_correlation_s > 0.0)) return "phase noise correlation time must be positive";
    if (!(o.parameter_update_s >= kNodeInterval_s - 1e-12 && o.parameter_update_s <= 1.0) ||
        std::abs(o.parameter_update_s / kNodeInterval_s - std::round(o.parameter_update_s / kNodeInterval_s)) > 1e-6)
      return "parameter update interval must be a whole number of milliseconds within 1 ms..1 s";
    for (const auto& imp : o.antenna_impairments) {
      if (!std::isfinite(imp.line_bias_cycles)) return "line bias must be finite";
      if (!(imp.phase_noise_m >= 0.0 && imp.phase_noise_m < 1.0)) return "phase noise must be within [0, 1) m";
    }
    for (const auto& e : o.cycle_slips) {
      if (e.prn < kMinPrn || e.prn > kMaxPrn) return "cycle slip: PRN must be 1..32";
      if (e.antenna < 0 || !(e.time_s >= 0.0) || !std::isfinite(e.cycles) || !(e.fade_s >= 0.0))
        return "cycle slip: antenna >= 0, time_s >= 0, finite cycles and fade_s >= 0 are needed";
    }
    for (const auto& b : o.blockages)
      if (b.antenna < 0 || !(b.start_s >= 0.0) || !(b.duration_s > 0.0))
        return "blockage: antenna >= 0, start_s >= 0 and duration_s > 0 are needed";
    for (const auto& c : o.cn0_steps) {
      if (c.antenna < 0 || !(c.start_s >= 0.0 && c.start_s <= 86400.0))
        return "C/N0 step: antenna >= 0 and start_s within 0..86400 s are needed";
      if (!(c.cn0_dbhz >= 0.0 && c.cn0_dbhz <= 80.0)) return "C/N0 step: cn0_dbhz must be within 0..80 dB-Hz";
      for (int prn : c.prns)
        if (prn < kMinPrn || prn > kMaxPrn) return "C/N0 step: PRN must be 1..32";
    }
    return {};
  }();
  if (why) *why = problem;
  return problem.empty();
}

std::int64_t cn0_step_first_sample(const Cn0StepEvent& step, double sample_rate_hz) {
  // A start on a sample (to rounding) is that sample; otherwise the next one.
  const double x = step.start_s * sample_rate_hz;
  const double nearest = std::round(x);
  return static_cast<std::int64_t>(std::abs(x - nearest) < 1e-6 ? nearest : std::ceil(x));
}

IfSynthesiser::IfSynthesiser(SynthesiserOptions options, std::vector<Ephemeris> ephemerides,
                             std::shared_ptr<const ReceiverMotion> motion)
    : options_(std::move(options)), motion_(std::move(motion)) {
  if (const auto err = io::why_invalid(options_); !err.empty()) throw std::invalid_argument(err);
  if (!motion_ || motion_->antenna_count() < 1) throw std::invalid_argument("the receiver needs at least one antenna");
  const int antennas = motion_->antenna_count();
  for (std::size_t a = static_cast<std::size_t>(antennas); a < options_.antenna_impairments.size(); ++a)
    if (options_.antenna_impairments[a].line_bias_cycles != 0.0 || options_.antenna_impairments[a].phase_noise_m != 0.0)
      throw std::invalid_argument("impairments for antenna " + std::to_string(a) + ": no such antenna");
  for (const auto& e : options_.cycle_slips)
    if (e.antenna >= antennas)
      throw std::invalid_argument("cycle slip on antenna " + std::to_string(e.antenna) + ": no such antenna");
  for (const auto& b : options_.blockages)
    if (b.antenna >= antennas)
      throw std::invalid_argument("blockage of antenna " + std::to_string(b.antenna) + ": no such antenna");
  for (const auto& c : options_.cn0_steps)
    if (c.antenna >= antennas)
      throw std::invalid_argument("C/N0 step on antenna " + std::to_string(c.antenna) + ": no such antenna");
  impl_ = std::make_unique<Impl>(options_, *motion_);
  Impl& m = *impl_;
  m.block_samples = std::max<std::int64_t>(1, std::llround(options_.sample_rate_hz * kNodeInterval_s));
  m.update_blocks = std::max<std::int64_t>(1, std::llround(options_.parameter_update_s / kNodeInterval_s));
  m.visibility_blocks =
      std::max<std::int64_t>(1, std::llround(kVisibilityInterval_s * options_.sample_rate_hz / m.block_samples));
  m.frac20_s = floor_mod(options_.start.tow_s, kTwentyMs_s);

  std::set<int> seen;
  for (const auto& eph : ephemerides) {
    if (eph.prn < kMinPrn || eph.prn > kMaxPrn) throw std::invalid_argument("ephemeris PRN out of 1..32");
    if (!seen.insert(eph.prn).second) throw std::invalid_argument("two ephemerides for PRN " + std::to_string(eph.prn));
    if (eph.health != 0 && !options_.include_unhealthy) continue;
    Impl::Sat sat;
    sat.eph = eph;
    auto it = options_.cn0_dbhz_by_prn.find(eph.prn);
    sat.cn0_dbhz = it != options_.cn0_dbhz_by_prn.end() ? it->second : options_.default_cn0_dbhz;
    const double cn0 = std::pow(10.0, sat.cn0_dbhz / 10.0);
    sat.amplitude = options_.real_output ? 2.0 * std::sqrt(cn0 / options_.sample_rate_hz)
                                         : std::sqrt(2.0 * cn0 / options_.sample_rate_hz);
    m.sats.push_back(std::move(sat));
  }
  const int n_ant = motion_->antenna_count();
  m.geo0.resize(n_ant);
  m.geo1.resize(n_ant);
  m.tracks.resize(static_cast<std::size_t>(n_ant) * m.sats.size());
  for (int a = 0; a < n_ant; ++a) {
    m.noise.emplace_back(options_.seed, 1000 + static_cast<std::uint64_t>(a));
    for (std::size_t k = 0; k < m.sats.size(); ++k) {
      auto& tr = m.tracks[static_cast<std::size_t>(a) * m.sats.size() + k];
      tr.rng.seed(options_.seed * 1000003ULL + 7919ULL * static_cast<std::uint64_t>(a) +
                  static_cast<std::uint64_t>(m.sats[k].eph.prn));
      if (options_.nav_data)
        tr.lnav = std::make_unique<LnavTransmitter>(m.sats[k].eph, options_.klobuchar, options_.utc, ephemerides,
                                                    options_.lnav);
    }
  }
  // C/N0 steps: per track, in sample order (a later entry wins a tie, as it comes later in the list).
  for (const auto& c : options_.cn0_steps) {
    const std::int64_t first = cn0_step_first_sample(c, options_.sample_rate_hz);
    m.step_samples.push_back(first);
    for (std::size_t k = 0; k < m.sats.size(); ++k) {
      if (!c.prns.empty() && std::find(c.prns.begin(), c.prns.end(), m.sats[k].eph.prn) == c.prns.end()) continue;
      auto& levels = m.tracks[static_cast<std::size_t>(c.antenna) * m.sats.size() + k].levels;
      const auto scale = static_cast<float>(std::pow(10.0, (c.cn0_dbhz - m.sats[k].cn0_dbhz) / 20.0));
      const auto at = std::upper_bound(levels.begin(), levels.end(), first,
                                       [](std::int64_t s, const Impl::Level& l) { return s < l.first_sample; });
      levels.insert(at, {first, c.cn0_dbhz, scale});
    }
  }
  std::sort(m.step_samples.begin(), m.step_samples.end());
  m.step_samples.erase(std::unique(m.step_samples.begin(), m.step_samples.end()), m.step_samples.end());
  // Automatic gain from the expected power of noise plus the satellites in view at the start, each at its
  // strongest level over the run (steps included) on any antenna.
  m.update_visibility(0);
  double power = 1.0;
  for (std::size_t k = 0; k < m.sats.size(); ++k) {
    if (!m.sats[k].active) continue;
    double scale = 1.0;
    for (int a = 0; a < n_ant; ++a)
      for (const auto& l : m.tracks[static_cast<std::size_t>(a) * m.sats.size() + k].levels)
        scale = std::max(scale, std::pow(10.0, (l.cn0_dbhz - m.sats[k].cn0_dbhz) / 20.0));
    power += 0.5 * std::pow(scale * m.sats[k].amplitude, 2);
  }
  gain_ = options_.output_rms / std::sqrt(power);
  for (auto& sat : m.sats) {
    const auto& chips = ca_code(sat.eph.prn);
    for (int i = 0; i < kCaCodeLength_chips; ++i)
      sat.chip_amplitude[i] = static_cast<float>(gain_ * sat.amplitude * chips[i]);
  }
}

IfSynthesiser::~IfSynthesiser() = default;

int IfSynthesiser::antenna_count() const { return motion_->antenna_count(); }

void IfSynthesiser::generate(std::span<const std::span<std::complex<float>>> out) {
  Impl& m = *impl_;
  if (out.size() != static_cast<std::size_t>(antenna_count()))
    throw std::invalid_argument("generate: one output span per antenna is needed");
  const std::size_t count = out[0].size();
  for (const auto& o : out)
    if (o.size() != count) throw std::invalid_argument("generate: all antenna spans must have the same size");
  std::size_t done = 0;
  while (done < count) {
    const std::int64_t block = next_sample_ / m.block_samples;
    if (block != m.current_block) m.enter_block(block);
    std::int64_t block_end = (block + 1) * m.block_samples;
    // A C/N0 step inside the block ends the segment there (sample-exact steps).
    const auto step = std::upper_bound(m.step_samples.begin(), m.step_samples.end(), next_sample_);
    if (step != m.step_samples.end()) block_end = std::min(block_end, *step);
    const std::size_t seg = static_cast<std::size_t>(
        std::min<std::int64_t>(block_end - next_sample_, static_cast<std::int64_t>(count - done)));
    for (std::size_t a = 0; a < out.size(); ++a) {
      std::complex<float>* dst = out[a].data() + done;
      if (options_.noise) {
        m.noise[a].fill(dst, seg, static_cast<float>(gain_), options_.real_output);
      } else {
        std::fill(dst, dst + seg, std::complex<float>(0.0f, 0.0f));
      }
      const double tau = m.tau_of(next_sample_);
      for (std::size_t k = 0; k < m.sats.size(); ++k)
        if (m.sats[k].active && !m.absent(m.sats[k].eph.prn, static_cast<int>(a), tau))
          m.add_satellite(k, static_cast<int>(a), next_sample_, dst, seg);
    }
    done += seg;
    next_sample_ += static_cast<std::int64_t>(seg);
  }
}

std::vector<SatelliteView> IfSynthesiser::visible_satellites(std::int64_t sample) {
  Impl& m = *impl_;
  const double tau = m.tau_of(sample);
  const RxGeo rx = m.rx_geo(0, tau);
  // Central difference over 1 ms (one-sided at the very start: the clock has no past before sample 0).
  const double tau_minus = std::max(0.0, tau - kDopplerHalfStep_s);
  const RxGeo rx_minus = m.rx_geo(0, tau_minus);
  const RxGeo rx_plus = m.rx_geo(0, tau_minus + 2.0 * kDopplerHalfStep_s);
  std::vector<SatelliteView> views;
  for (const auto& sat : m.sats) {
    const Solution s = m.solve(sat, rx, 0.075, 0.0);
    if (s.timing.elevation_rad < options_.elevation_mask_rad) continue;
    const Solution sm = m.solve(sat, rx_minus, s.travel_s, s.d_code_s);
    const Solution sp = m.solve(sat, rx_plus, s.travel_s, s.d_code_s);
    SatelliteView v;
    v.prn = sat.eph.prn;
    v.elevation_rad = s.timing.elevation_rad;
    v.azimuth_rad = s.timing.azimuth_rad;
    v.cn0_dbhz = cn0_dbhz(sat.eph.prn, 0, sample);
    v.doppler_hz = (sp.carrier_cycles - sm.carrier_cycles) / (2.0 * kDopplerHalfStep_s) - options_.if_hz;
    v.code_phase_chips = s.timing.code_phase_chips;
    views.push_back(v);
  }
  return views;
}

SignalTiming IfSynthesiser::timing(int prn, int antenna, std::int64_t sample) {
  Impl& m = *impl_;
  for (const auto& sat : m.sats) {
    if (sat.eph.prn != prn) continue;
    return m.solve(sat, m.rx_geo(antenna, m.tau_of(sample)), 0.075, 0.0).timing;
  }
  throw std::out_of_range("no transmitted satellite with PRN " + std::to_string(prn));
}

ReceiverClockState IfSynthesiser::receiver_clock(std::int64_t sample) { return impl_->clock.at(impl_->tau_of(sample)); }

double IfSynthesiser::receive_time_s(std::int64_t sample) {
  const double tau = impl_->tau_of(sample);
  return tau - (impl_->clock.at(tau).bias_s - options_.clock.bias_s);
}

double IfSynthesiser::cn0_dbhz(int prn, int antenna, std::int64_t sample) const {
  const Impl& m = *impl_;
  for (std::size_t k = 0; k < m.sats.size(); ++k) {
    if (m.sats[k].eph.prn != prn) continue;
    if (antenna < 0 || antenna >= antenna_count()) throw std::out_of_range("no antenna " + std::to_string(antenna));
    const Impl::Level* l = Impl::level_at(m.tracks[static_cast<std::size_t>(antenna) * m.sats.size() + k], sample);
    return l ? l->cn0_dbhz : m.sats[k].cn0_dbhz;
  }
  throw std::out_of_range("no transmitted satellite with PRN " + std::to_string(prn));
}

double IfSynthesiser::amplitude(int prn) const {
  for (const auto& sat : impl_->sats)
    if (sat.eph.prn == prn) return gain_ * sat.amplitude;
  throw std::out_of_range("no transmitted satellite with PRN " + std::to_string(prn));
}

}  // namespace ultratrack::signals
