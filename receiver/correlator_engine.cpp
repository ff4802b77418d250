#include "receiver/correlator_engine.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "signals/ca_code.hpp"

namespace ultratrack::receiver {
namespace {

constexpr int kCodeLength = signals::kCaCodeLength_chips;
constexpr int kChunk = 256;  // samples per inner pass: the replica buffers stay in L1
constexpr int kLanes = 8;    // independent partial sums, so the compiler can vectorise without reassociation

// Quadrant rotation by integer arithmetic, then Taylor series on |theta| <= pi/4 (truncation < 3e-8).
inline void sincos_q32(std::uint32_t phase, float& c_out, float& s_out) {
  const std::uint32_t quadrant = ((phase + (1u << 29)) >> 30) & 3u;
  const auto residual = static_cast<std::int32_t>(phase - (quadrant << 30));  // [-2^29, 2^29)
  const float theta = static_cast<float>(residual) * static_cast<float>(2.0 * 3.14159265358979323846 / 4294967296.0);
  const float t2 = theta * theta;
  const float c = 1.0f + t2 * (-0.5f + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320))));
  const float s = theta * (1.0f + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 * (1.0f / 362880)))));
  c_out = quadrant == 0 ? c : quadrant == 1 ? -s : quadrant == 2 ? -c : s;
  s_out = quadrant == 0 ? s : quadrant == 1 ? c : quadrant == 2 ? -s : -c;
}

template <int kTaps>
void correlate_chunked(const std::int8_t* table, const double* offsets, std::span<const std::complex<float>* const> antennas,
                       int num_samples, const ReplicaSegment& rep, std::span<TapSums> sums) {
  alignas(64) float carrier_cos[kChunk];
  alignas(64) float carrier_sin[kChunk];
  alignas(64) float code[kTaps][kChunk];
  const int num_antennas = static_cast<int>(antennas.size());

  for (int start = 0; start < num_samples; start += kChunk) {
    const int n = num_samples - start < kChunk ? num_samples - start : kChunk;
    const std::uint32_t phase0 = rep.carrier_phase_q32 + rep.carrier_step_q32 * static_cast<std::uint32_t>(start);
    for (int i = 0; i < n; ++i) {
      float c, s;
      sincos_q32(phase0 + rep.carrier_step_q32 * static_cast<std::uint32_t>(i), c, s);
      carrier_cos[i] = c;
      carrier_sin[i] = s;
    }
    const double code0 = rep.code_phase_chips + rep.code_step_chips * start + 2 * kCodeLength;  // table origin
    // Chip index = whole part of the chunk's start (exact, integer) + float offset within the chunk: the float
    // part stays below ~kChunk * step chips, so its rounding is < 1e-5 chips and never accumulates.
    const auto step_f = static_cast<float>(rep.code_step_chips);
    for (int t = 0; t < kTaps; ++t) {
      const double base = code0 + offsets[t];
      const int whole = static_cast<int>(base);
      const auto frac = static_cast<float>(base - whole);
      const std::int8_t* __restrict chips = table + whole;
      float* __restrict out = code[t];
      for (int i = 0; i < n; ++i) out[i] = chips[static_cast<int>(frac + step_f * static_cast<float>(i))];
    }
    for (int a = 0; a < num_antennas; ++a) {
      const float* __restrict x = reinterpret_cast<const float*>(antennas[a] + start);
      float acc_re[kTaps][kLanes] = {};
      float acc_im[kTaps][kLanes] = {};
      const int n_lanes = n - n % kLanes;
      for (int i = 0; i < n_lanes; i += kLanes) {
        for (int l = 0; l < kLanes; ++l) {
          const float xr = x[2 * (i + l)], xi = x[2 * (i + l) + 1];
          const float cr = carrier_cos[i + l], ci = carrier_sin[i + l];
          // x * exp(-j phase)
          const float wr = xr * cr + xi * ci;
          const float wi = xi * cr - xr * ci;
          for (int t = 0; t < kTaps; ++t) {
            acc_re[t][l] += wr * code[t][i + l];
            acc_im[t][l] += wi * code[t][i + l];
          }
        }
      }
      for (int i = n_lanes; i < n; ++i) {
        const float xr = x[2 * i], xi = x[2 * i + 1];
        const float wr = xr * carrier_cos[i] + xi * carrier_sin[i];
        const float wi = xi * carrier_cos[i] - xr * carrier_sin[i];
        for (int t = 0; t < kTaps; ++t) {
          acc_re[t][0] += wr * code[t][i];
          acc_im[t][0] += wi * code[t][i];
        }
      }
      for (int t = 0; t < kTaps; ++t) {
        double re = 0.0, im = 0.0;
        for (int l = 0; l < kLanes; ++l) {
          re += acc_re[t][l];
          im += acc_im[t][l];
        }
        sums[a][t] += std::complex<double>(re, im);
      }
    }
  }
}

}  // namespace

CorrelatorEngine::CorrelatorEngine(int prn, std::span<const double> tap_offsets_chips)
    : prn_(prn), num_taps_(static_cast<int>(tap_offsets_chips.size())) {
  if (num_taps_ < 1 || num_taps_ > kMaxTaps)
    throw std::invalid_argument("CorrelatorEngine: 1.." + std::to_string(kMaxTaps) + " taps required");
  for (int t = 0; t < num_taps_; ++t) {
    if (!(std::abs(tap_offsets_chips[t]) <= kCodeLength))
      throw std::invalid_argument("CorrelatorEngine: tap offset beyond one code period");
    offsets_[t] = tap_offsets_chips[t];
  }
  const auto& chips = signals::ca_code(prn);  // throws std::out_of_range for a bad PRN
  table_.resize(5 * kCodeLength + 8);
  for (int i = 0; i < static_cast<int>(table_.size()); ++i) table_[i] = chips[i % kCodeLength];
}

void CorrelatorEngine::correlate(std::span<const std::complex<float>* const> antennas, int num_samples,
                                 const ReplicaSegment& replica, std::span<TapSums> sums) const {
  const std::int8_t* table = table_.data();
  const double* off = offsets_.data();
  switch (num_taps_) {
    case 1: correlate_chunked<1>(table, off, antennas, num_samples, replica, sums); break;
    case 2: correlate_chunked<2>(table, off, antennas, num_samples, replica, sums); break;
    case 3: correlate_chunked<3>(table, off, antennas, num_samples, replica, sums); break;
    case 4: correlate_chunked<4>(table, off, antennas, num_samples, replica, sums); break;
    case 5: correlate_chunked<5>(table, off, antennas, num_samples, replica, sums); break;
    default: correlate_chunked<6>(table, off, antennas, num_samples, replica, sums); break;
  }
}

double noise_tap_offset_chips(int prn) {
  const auto& c = signals::ca_code(prn);
  auto autocorr = [&](int lag) {
    int s = 0;
    for (int k = 0; k < kCodeLength; ++k) s += c[k] * c[(k + lag) % kCodeLength];
    return s;
  };
  for (int lag = 300; lag <= 723; ++lag) {
    bool clean = true;
    for (int d = -2; d <= 2 && clean; ++d) clean = autocorr(lag + d) == -1;
    if (clean) return -lag;
  }
  throw std::logic_error("noise_tap_offset_chips: no clean lag for PRN " + std::to_string(prn));
}

void fixed_point_sincos(std::uint32_t phase_q32, float* cos_out, float* sin_out) {
  sincos_q32(phase_q32, *cos_out, *sin_out);
}

}  // namespace ultratrack::receiver
