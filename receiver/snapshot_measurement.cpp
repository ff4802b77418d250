// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/snapshot_measurement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "receiver/acquisition.hpp"
#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCodeLength = signals::kCaCodeLength_chips;

int coherent_ms_for(const SnapshotSearchOptions& o, std::size_t samples) {
  if (o.coherent_ms > 0) return o.coherent_ms;
  const double length_ms = static_cast<double>(samples) / o.fs_hz * 1e3;
  return length_ms >= 40.0 ? 10 : 5;
}

// Non-coherent powers of the correlations with replicas started at code phases phases_chips[j] at sample 0,
// summed over the coherent blocks of `block` samples (one carrier wipe-off for all of them).
template <std::size_t N>
std::array<double, N> correlation_powers(std::span<const std::complex<float>> samples, const signals::CaCodeChips& code,
                                         const std::array<double, N>& phases_chips, double chips_per_sample,
                                         double doppler_hz, double fs_hz, std::size_t block) {
  const std::size_t blocks = samples.size() / block;
  const double carrier_step = -2.0 * kPi * doppler_hz / fs_hz;
  std::array<double, N> power{};
  for (std::size_t b = 0; b < blocks; ++b) {
    std::array<std::complex<double>, N> sum{};
    const std::size_t first = b * block;
    // Carrier phasor and code phases recomputed exactly at each block start, advanced incrementally inside it.
    std::complex<double> phasor = std::polar(1.0, carrier_step * static_cast<double>(first));
    const std::complex<double> rotate = std::polar(1.0, carrier_step);
    std::array<double, N> chip{};
    for (std::size_t j = 0; j < N; ++j) {
      chip[j] = std::fmod(phases_chips[j] + static_cast<double>(first) * chips_per_sample, kCodeLength);
      if (chip[j] < 0.0) chip[j] += kCodeLength;
    }
    for (std::size_t k = 0; k < block; ++k) {
      const std::complex<double> wiped = std::complex<double>(samples[first + k]) * phasor;
      for (std::size_t j = 0; j < N; ++j) {
        sum[j] += static_cast<double>(code[static_cast<std::size_t>(chip[j])]) * wiped;
        chip[j] += chips_per_sample;
        if (chip[j] >= kCodeLength) chip[j] -= kCodeLength;
      }
      phasor *= rotate;
    }
    for (std::size_t j = 0; j < N; ++j) power[j] += std::norm(sum[j]);
  }
  return power;
}

}  // namespace

bool SnapshotSearchOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(fs_hz >= 1.023e6)) return fail("sample rate must be >= 1.023 MHz");
  if (!(doppler_max_hz > 0.0 && doppler_max_hz <= fs_hz / 4.0)) return fail("Doppler range must be in (0, fs/4]");
  if (!(pfa > 0.0 && pfa <= 0.5)) return fail("pfa must be in (0, 0.5]");
  if (coherent_ms < 0 || coherent_ms > 10) return fail("coherent time must be 0 (automatic) or 1..10 ms");
  if (!(spacing_chips > 0.0 && spacing_chips <= 1.5)) return fail("early-late spacing must be in (0, 1.5] chips");
  if (!(min_metric_ratio >= 1.0)) return fail("minimum metric ratio must be >= 1");
  return true;
}

std::vector<SnapshotDetection> measure_snapshot(std::span<const std::complex<float>> samples,
                                                const std::vector<int>& prns, const SnapshotSearchOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("measure_snapshot: " + why);
  const int coherent_ms = coherent_ms_for(options, samples.size());
  const auto block = static_cast<std::size_t>(std::llround(options.fs_hz * coherent_ms * 1e-3));
  const std::size_t blocks = samples.size() / block;
  if (blocks < 2) throw std::invalid_argument("measure_snapshot: the snapshot is shorter than 2 coherent blocks");
  // The search runs at about 4 MHz: sums of `decimation` samples (a boxcar low-pass: a few tenths of a dB of
  // the code's main lobe) centred (decimation - 1) / 2 samples after each group's first. The fine loop uses every
  // sample.
  const int decimation = std::max(1, static_cast<int>(options.fs_hz / 4.0e6));
  std::vector<std::complex<float>> reduced;
  std::span<const std::complex<float>> searched = samples;
  if (decimation > 1) {
    reduced.resize(samples.size() / static_cast<std::size_t>(decimation));
    for (std::size_t i = 0; i < reduced.size(); ++i) {
      std::complex<float> sum = 0.0f;
      for (int k = 0; k < decimation; ++k)
        sum += samples[i * static_cast<std::size_t>(decimation) + static_cast<std::size_t>(k)];
      reduced[i] = sum;
    }
    searched = reduced;
  }
  AcquisitionOptions acq;
  acq.fs_hz = options.fs_hz / decimation;
  acq.coherent_ms = coherent_ms;
  acq.doppler_max_hz = options.doppler_max_hz;
  acq.pfa = options.pfa;
  const auto reduced_block = static_cast<std::size_t>(std::llround(acq.fs_hz * acq.coherent_s()));
  acq.noncoherent = static_cast<int>(std::clamp<std::size_t>(searched.size() / reduced_block, 1, 1000));
  Acquisition acquisition(acq);
  const auto found = acquisition.search(searched.first(acquisition.samples_needed()), prns);

  const double total_s = static_cast<double>(blocks * block) / options.fs_hz;
  const auto used = samples.first(blocks * block);
  const double d = options.spacing_chips;
  std::vector<SnapshotDetection> out;
  double strongest_dbhz = -1e9;
  for (const AcquisitionResult& r : found)
    if (r.detected) strongest_dbhz = std::max(strongest_dbhz, r.cn0_dbhz);
  for (const AcquisitionResult& r : found) {
    const bool strong = r.metric >= options.min_metric_ratio * r.threshold;
    const bool near_strongest = r.cn0_dbhz >= strongest_dbhz - options.cross_correlation_margin_db;
    if (!r.detected || (!strong && !near_strongest)) continue;
    const signals::CaCodeChips& code = signals::ca_code(r.prn);
    const double chips_per_sample =
        signals::kCaChipRate_hz * (1.0 + r.doppler_hz / signals::kL1Frequency_hz) / options.fs_hz;
    // Noise alone: a replica half a code period away from the peak.
    const double noise = correlation_powers<1>(used, code, {r.code_phase_chips + kCodeLength / 2.0}, chips_per_sample,
                                               r.doppler_hz, options.fs_hz, block)[0];
    // The search's code phase is at its first (decimated) sample, (decimation - 1) / 2 input samples in.
    double phase = r.code_phase_chips - 0.5 * (decimation - 1) * chips_per_sample;
    for (int iteration = 0; iteration < 5; ++iteration) {
      const auto p = correlation_powers<2>(used, code, {phase - d / 2.0, phase + d / 2.0}, chips_per_sample,
                                           r.doppler_hz, options.fs_hz, block);
      const double early = std::sqrt(std::max(p[0] - noise, 0.0)), late = std::sqrt(std::max(p[1] - noise, 0.0));
      if (early + late <= 0.0) break;
      // The received code phase at sample 0 is later than the replica's when late > early.
      phase += std::clamp((1.0 - d / 2.0) * (late - early) / (early + late), -0.5, 0.5);
    }
    phase = std::fmod(phase, kCodeLength);
    if (phase < 0.0) phase += kCodeLength;
    SnapshotDetection det;
    det.prn = r.prn;
    det.code_phase_chips = phase;
    det.doppler_hz = r.doppler_hz;
    det.cn0_dbhz = r.cn0_dbhz;
    det.acquisition_metric = r.metric;
    det.acquisition_threshold = r.threshold;
    const double cn0 = std::pow(10.0, r.cn0_dbhz / 10.0);
    det.code_sigma_chips = std::sqrt(d / (4.0 * cn0 * total_s) * (1.0 + 2.0 / ((2.0 - d) * cn0 * acq.coherent_s())));
    // Fine search resolution step / 8 (uniform: / sqrt(12)) and the frequency estimate's thermal floor.
    const double resolution = acq.step_hz() / 8.0 / std::sqrt(12.0);
    const double thermal = 1.0 / (2.0 * kPi * total_s) * std::sqrt(12.0 / (cn0 * total_s));
    det.doppler_sigma_hz = std::sqrt(resolution * resolution + thermal * thermal) + 1.0;
    out.push_back(det);
  }
  return out;
}

}  // namespace ultratrack::receiver
