// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/acquisition.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kChipRate_hz = signals::kCaChipRate_hz;
constexpr int kCodeLength = signals::kCaCodeLength_chips;

// log(sum_{i<K} g^i / i!) by log-sum-exp (terms grow then shrink; K up to 1000).
double log_partial_exp_series(int k, double g) {
  if (g <= 0.0) return 0.0;  // only the i = 0 term, which is 1
  std::vector<double> log_terms(static_cast<std::size_t>(k));
  double largest = -INFINITY;
  for (int i = 0; i < k; ++i) {
    log_terms[static_cast<std::size_t>(i)] = i * std::log(g) - std::lgamma(i + 1.0);
    largest = std::max(largest, log_terms[static_cast<std::size_t>(i)]);
  }
  double sum = 0.0;
  for (double t : log_terms) sum += std::exp(t - largest);
  return largest + std::log(sum);
}

// Code chip (+1/-1) at a code phase in chips (any real number; the code repeats every 1023 chips).
inline float chip_at(const signals::CaCodeChips& code, double phase_chips) {
  double wrapped = phase_chips - kCodeLength * std::floor(phase_chips / kCodeLength);
  auto index = static_cast<int>(wrapped);
  if (index >= kCodeLength) index = kCodeLength - 1;  // rounding at the upper edge
  return static_cast<float>(code[static_cast<std::size_t>(index)]);
}

// Code chip rate of a signal with carrier Doppler doppler_hz (the code Doppler is coherent with it).
inline double code_rate_hz(double doppler_hz) { return kChipRate_hz * (1.0 + doppler_hz / signals::kL1Frequency_hz); }

}  // namespace

bool AcquisitionOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string why) {
    if (error) *error = std::move(why);
    return false;
  };
  if (!(fs_hz >= kChipRate_hz) || !std::isfinite(fs_hz)) return fail("sample rate must be at least 1.023 MHz");
  if (coherent_ms < 1 || coherent_ms > 10) return fail("coherent integration must be 1 to 10 ms");
  if (noncoherent < 1 || noncoherent > 1000) return fail("non-coherent blocks must be 1 to 1000");
  if (!(doppler_max_hz > 0.0) || doppler_max_hz > fs_hz / 4.0)
    return fail("Doppler range must be positive and at most fs/4");
  if (doppler_step_hz < 0.0 || doppler_step_hz > 1.0 / coherent_s() || !std::isfinite(doppler_step_hz))
    return fail("Doppler step must be 0 (automatic) or within (0, 1/T_coh]");
  if (!(pfa > 0.0) || pfa > 0.5) return fail("false-alarm probability must be within (0, 0.5]");
  return true;
}

double acquisition_threshold(int noncoherent, double cells, double pfa) {
  if (noncoherent < 1 || !(cells >= 1.0) || !(pfa > 0.0 && pfa < 1.0))
    throw std::invalid_argument("acquisition_threshold: K >= 1, cells >= 1, 0 < pfa < 1");
  // Per-cell probability so that 1 - (1 - p)^M = pfa, without cancellation for tiny p.
  const double log_p_cell = std::log(-std::expm1(std::log1p(-pfa) / cells));
  auto log_tail = [&](double g) { return -g + log_partial_exp_series(noncoherent, g); };
  double lo = 0.0, hi = 1.0;
  while (log_tail(hi) > log_p_cell) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (log_tail(mid) > log_p_cell ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Acquisition::Acquisition(const AcquisitionOptions& options) : options_(options) {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("acquisition options: " + why);
  block_size_ = static_cast<std::size_t>(std::llround(options_.fs_hz * options_.coherent_s()));
  samples_per_chip_ = options_.fs_hz / kChipRate_hz;
  // Folding: with a whole number P of samples per code period, a T_coh-long block (Doppler removed) summed
  // period by period into P samples has exactly the same circular correlation with the one-period replica,
  // so the FFTs are P points long whatever T_coh is. Otherwise the FFTs span the whole block.
  const double period = kCodeLength * samples_per_chip_;
  const auto whole_period = static_cast<std::size_t>(std::llround(period));
  const bool fold = std::abs(period - static_cast<double>(whole_period)) < 1e-6 &&
                    block_size_ == whole_period * static_cast<std::size_t>(options_.coherent_ms);
  fft_size_ = fold ? whole_period : block_size_;
  lags_ = std::min(fft_size_, static_cast<std::size_t>(std::ceil(period)));
  // Rotation (file comment of the header): R grid steps per FFT bin, when that is a whole number.
  const double per_fft_bin = options_.fs_hz / static_cast<double>(fft_size_) / options_.step_hz();
  const double whole = std::round(per_fft_bin);
  rotation_ = whole >= 1.0 && std::abs(per_fft_bin - whole) < 1e-6 ? static_cast<std::size_t>(whole) : 0;
  segment_ = static_cast<std::size_t>(std::max<long long>(1, std::llround(options_.fs_hz * 1e-4)));
  forward_ = FftwPlan(fft_size_, FftwPlan::Direction::kForward);
  backward_ = FftwPlan(fft_size_, FftwPlan::Direction::kBackward);
  scratch_.push_back(std::make_unique<Scratch>(fft_size_, lags_));
  code_spectra_.resize(signals::kMaxPrn);
}

Acquisition::Scratch::Scratch(std::size_t fft_size, std::size_t lags)
    : mixed(fft_size), product(fft_size), correlation(fft_size), spectrum(fft_size), grid(lags) {}

template <class F>
void Acquisition::spread(WorkerPool* pool, int n, F&& f) {
  const int jobs = pool ? std::min(pool->threads(), n) : 1;
  if (jobs <= 1) {
    for (int i = 0; i < n; ++i) f(i, *scratch_[0]);
    return;
  }
  while (scratch_.size() < static_cast<std::size_t>(jobs))
    scratch_.push_back(std::make_unique<Scratch>(fft_size_, lags_));
  // One job per scratch set; each takes the next item until none is left. Items are independent, so which
  // thread computes which does not change any result.
  std::atomic<int> next{0};
  auto job = [&](int j) {
    Scratch& s = *scratch_[static_cast<std::size_t>(j)];
    for (int i = next.fetch_add(1); i < n; i = next.fetch_add(1)) f(i, s);
  };
  pool->parallel_for(jobs, job);
}

double Acquisition::cells() const { return static_cast<double>(doppler_grid(std::nullopt).size() * lags_); }

std::vector<double> Acquisition::doppler_grid(std::optional<DopplerWindow> assist) const {
  const double step = options_.step_hz();
  const double center = assist ? assist->center_hz : 0.0;
  const double half_width = assist ? std::max(assist->half_width_hz, 0.0) : options_.doppler_max_hz;
  const int half_bins = static_cast<int>(std::ceil(half_width / step - 1e-9));
  std::vector<double> grid;
  for (int i = -half_bins; i <= half_bins; ++i) grid.push_back(center + i * step);
  return grid;
}

const FftwBuffer& Acquisition::code_spectrum(int prn) {
  auto& slot = code_spectra_[static_cast<std::size_t>(prn - 1)];
  if (!slot) {
    // Replica sampled at the actual rate (non-integer samples per chip), code phase 0 at sample 0,
    // as conj(FFT) / F so that IFFT(X conj(C) / F) is the plain correlation sum.
    const auto& code = signals::ca_code(prn);
    FftwBuffer& mixed = scratch_[0]->mixed;
    for (std::size_t m = 0; m < fft_size_; ++m)
      mixed[m] = {chip_at(code, static_cast<double>(m) / samples_per_chip_), 0.0f};
    FftwBuffer spectrum(fft_size_);
    forward_.execute(mixed, spectrum);
    const float scale = 1.0f / static_cast<float>(fft_size_);
    for (std::size_t i = 0; i < fft_size_; ++i) spectrum[i] = std::conj(spectrum[i]) * scale;
    slot = std::move(spectrum);
  }
  return *slot;
}

void Acquisition::doppler_spectrum(std::span<const std::complex<float>> samples, int block, double doppler_hz,
                                   FftwBuffer& out, Scratch& s) const {
  // Carrier wipe-off as x[m] * base[m % 256] * anchor[m / 256]: 256 phasors from a double recursion, anchors
  // exact in double, and a plain float inner loop (real arithmetic, no complex-multiply NaN path) that vectorises.
  constexpr std::size_t kChunk = 256;
  const std::size_t first = static_cast<std::size_t>(block) * block_size_;
  const double cycles_per_sample = doppler_hz / options_.fs_hz;
  const std::complex<double> step = std::polar(1.0, -kTwoPi * cycles_per_sample);
  std::complex<double> p(1.0, 0.0);
  for (std::size_t m = 0; m < kChunk; ++m, p *= step) {
    s.base_re[m] = static_cast<float>(p.real());
    s.base_im[m] = static_cast<float>(p.imag());
  }
  std::fill(s.mixed.data(), s.mixed.data() + fft_size_, std::complex<float>{});
  auto* folded = reinterpret_cast<float*>(s.mixed.data());
  const auto* x = reinterpret_cast<const float*>(samples.data() + first);
  std::size_t at = 0;  // index into the folded buffer
  for (std::size_t chunk = 0; chunk * kChunk < block_size_; ++chunk) {
    const double turns = cycles_per_sample * static_cast<double>(chunk * kChunk);
    const std::complex<double> anchor = std::polar(1.0, -kTwoPi * (turns - std::floor(turns)));
    const auto a_re = static_cast<float>(anchor.real()), a_im = static_cast<float>(anchor.imag());
    const std::size_t count = std::min(kChunk, block_size_ - chunk * kChunk);
    for (std::size_t m = 0; m < count; ++m) {
      const float c_re = s.base_re[m] * a_re - s.base_im[m] * a_im;
      const float c_im = s.base_re[m] * a_im + s.base_im[m] * a_re;
      const float s_re = x[2 * (chunk * kChunk + m)], s_im = x[2 * (chunk * kChunk + m) + 1];
      folded[2 * at] += s_re * c_re - s_im * c_im;
      folded[2 * at + 1] += s_re * c_im + s_im * c_re;
      if (++at == fft_size_) at = 0;
    }
  }
  forward_.execute(s.mixed, out);
}

const FftwBuffer* Acquisition::signal_spectra(std::span<const std::complex<float>> samples,
                                              const std::vector<double>& dopplers, WorkerPool* pool) {
  const std::size_t bases = rotation_ > 0 ? std::min(rotation_, dopplers.size()) : dopplers.size();
  const auto k_blocks = static_cast<std::size_t>(options_.noncoherent);
  const std::size_t spectra = bases * k_blocks;
  if (spectra * fft_size_ * sizeof(std::complex<float>) > memory_budget_bytes_) return nullptr;
  while (spectrum_cache_.size() < spectra) spectrum_cache_.emplace_back(fft_size_);  // grows once, then reused
  spread(pool, static_cast<int>(spectra), [&](int i, Scratch& s) {
    const auto b = static_cast<std::size_t>(i) / k_blocks, k = static_cast<std::size_t>(i) % k_blocks;
    doppler_spectrum(samples, static_cast<int>(k), dopplers[b], spectrum_cache_[b * k_blocks + k], s);
  });
  return spectrum_cache_.data();
}

void Acquisition::correlate_bin(std::span<const std::complex<float>> samples, const FftwBuffer* spectra,
                                std::size_t shift, int prn, double doppler_hz, float* acc, Scratch& s) const {
  const FftwBuffer& code = *code_spectra_[static_cast<std::size_t>(prn - 1)];  // made before the search
  std::fill(acc, acc + lags_, 0.0f);
  // Code-phase drift per block from the code Doppler (and from N not being a whole number of periods).
  const double period = kCodeLength * options_.fs_hz / code_rate_hz(doppler_hz);
  const auto n = static_cast<std::ptrdiff_t>(fft_size_);
  for (int k = 0; k < options_.noncoherent; ++k) {
    const FftwBuffer* spectrum = spectra ? spectra + k : &s.spectrum;
    if (!spectra) doppler_spectrum(samples, k, doppler_hz, s.spectrum, s);
    // P[i] = X[(i + shift) mod F] C[i] in real arithmetic (std::complex's operator* carries a NaN-recovery
    // branch that stops vectorisation), in the two runs of the rotation.
    const float* x = reinterpret_cast<const float*>(spectrum->data());
    const float* c = reinterpret_cast<const float*>(code.data());
    float* p = reinterpret_cast<float*>(s.product.data());
    auto multiply = [&](std::size_t from, std::size_t to, const float* xs) {
      for (std::size_t i = from; i < to; ++i) {
        const float xr = xs[2 * i], xi = xs[2 * i + 1], cr = c[2 * i], ci = c[2 * i + 1];
        p[2 * i] = xr * cr - xi * ci;
        p[2 * i + 1] = xr * ci + xi * cr;
      }
    };
    multiply(0, fft_size_ - shift, x + 2 * shift);
    multiply(fft_size_ - shift, fft_size_, x + 2 * shift - 2 * fft_size_);
    backward_.execute(s.product, s.correlation);
    const double start = -static_cast<double>(k) * static_cast<double>(block_size_);
    std::ptrdiff_t lag_shift =
        static_cast<std::ptrdiff_t>(std::llround(start - period * std::round(start / period))) % n;
    if (lag_shift < 0) lag_shift += n;
    // acc[lag] += |corr[(lag + lag_shift) mod n]|^2, in the two unwrapped runs.
    const auto* y = reinterpret_cast<const float*>(s.correlation.data());
    const auto first_run =
        static_cast<std::size_t>(std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(lags_), n - lag_shift));
    const float* a = y + 2 * lag_shift;
    for (std::size_t lag = 0; lag < first_run; ++lag)
      acc[lag] += a[2 * lag] * a[2 * lag] + a[2 * lag + 1] * a[2 * lag + 1];
    const float* b = y - 2 * static_cast<std::ptrdiff_t>(first_run);
    for (std::size_t lag = first_run; lag < lags_; ++lag)
      acc[lag] += b[2 * lag] * b[2 * lag] + b[2 * lag + 1] * b[2 * lag + 1];
  }
}

void Acquisition::segment_sums(std::span<const std::complex<float>> samples, int prn, double doppler_hz,
                               double lag_samples, Scratch& s) const {
  const auto& code = signals::ca_code(prn);
  const std::size_t per_block = (block_size_ + segment_ - 1) / segment_;
  s.segment_re.resize(per_block * static_cast<std::size_t>(options_.noncoherent));  // no-ops after the first
  s.segment_im.resize(s.segment_re.size());
  const double chips_per_sample = code_rate_hz(doppler_hz) / options_.fs_hz;
  const double cycles_per_sample = doppler_hz / options_.fs_hz;
  const std::complex<double> step = std::polar(1.0, -kTwoPi * cycles_per_sample);
  const double step_re = step.real(), step_im = step.imag();
  for (int k = 0; k < options_.noncoherent; ++k) {
    const std::size_t first = static_cast<std::size_t>(k) * block_size_;
    double phase = (static_cast<double>(first) - lag_samples) * chips_per_sample;
    phase -= kCodeLength * std::floor(phase / kCodeLength);
    const auto* x = reinterpret_cast<const float*>(samples.data() + first);
    for (std::size_t j = 0; j < per_block; ++j) {
      const std::size_t from = j * segment_, to = std::min(block_size_, from + segment_);
      // The carrier phase relative to the block's first sample, exact at each segment's start.
      const double turns = cycles_per_sample * static_cast<double>(from);
      const std::complex<double> anchor = std::polar(1.0, -kTwoPi * (turns - std::floor(turns)));
      double nco_re = anchor.real(), nco_im = anchor.imag(), sum_re = 0.0, sum_im = 0.0;
      for (std::size_t m = from; m < to; ++m) {
        const double xr = x[2 * m], xi = x[2 * m + 1];
        const auto chip_index = std::min(static_cast<std::size_t>(phase), static_cast<std::size_t>(kCodeLength - 1));
        const double chip = code[chip_index];
        sum_re += (xr * nco_re - xi * nco_im) * chip;
        sum_im += (xr * nco_im + xi * nco_re) * chip;
        const double next_re = nco_re * step_re - nco_im * step_im;
        nco_im = nco_re * step_im + nco_im * step_re;
        nco_re = next_re;
        phase += chips_per_sample;
        if (phase >= kCodeLength) phase -= kCodeLength;
      }
      s.segment_re[static_cast<std::size_t>(k) * per_block + j] = sum_re;
      s.segment_im[static_cast<std::size_t>(k) * per_block + j] = sum_im;
    }
  }
}

double Acquisition::segment_power(const Scratch& s, double offset_hz) const {
  const std::size_t per_block = (block_size_ + segment_ - 1) / segment_;
  double power = 0.0;
  for (int k = 0; k < options_.noncoherent; ++k) {
    double re = 0.0, im = 0.0;
    for (std::size_t j = 0; j < per_block; ++j) {
      const std::size_t from = j * segment_, to = std::min(block_size_, from + segment_);
      // The offset's phase at the segment's centre, relative to the block's first sample.
      const double centre = 0.5 * static_cast<double>(from + to - 1);
      const double angle = -kTwoPi * offset_hz * centre / options_.fs_hz;
      const double c = std::cos(angle), sn = std::sin(angle);
      const double a = s.segment_re[static_cast<std::size_t>(k) * per_block + j];
      const double b = s.segment_im[static_cast<std::size_t>(k) * per_block + j];
      re += a * c - b * sn;
      im += a * sn + b * c;
    }
    power += re * re + im * im;
  }
  return power;
}

double Acquisition::power_at(std::span<const std::complex<float>> samples, int prn, double doppler_hz,
                             double lag_samples, Scratch& s) const {
  segment_sums(samples, prn, doppler_hz, lag_samples, s);
  return segment_power(s, 0.0);
}

AcquisitionResult Acquisition::search_grid(std::span<const std::complex<float>> samples, int prn,
                                           const std::vector<double>& dopplers, const FftwBuffer* spectra, Scratch& s,
                                           WorkerPool* pool) {
  std::vector<float>& grid = s.grid;
  std::vector<double>& row_noise = s.row_noise;
  const std::size_t bins = dopplers.size();
  if (grid.size() < bins * lags_) grid.resize(bins * lags_);
  row_noise.resize(bins);
  // The rows: independent, each written by one job into its own part of the grid.
  const auto k_blocks = static_cast<std::size_t>(options_.noncoherent);
  auto fill = [&](int i, Scratch& t) {
    const auto d = static_cast<std::size_t>(i);
    const std::size_t base = rotation_ > 0 ? d % rotation_ : d, shift = rotation_ > 0 ? d / rotation_ : 0;
    correlate_bin(samples, spectra ? spectra + base * k_blocks : nullptr, spectra ? shift : 0, prn, dopplers[d],
                  &grid[d * lags_], t);
  };
  if (pool) {
    spread(pool, static_cast<int>(bins), fill);
  } else {
    for (std::size_t d = 0; d < bins; ++d) fill(static_cast<int>(d), s);
  }
  // Index of a row's largest cell (the first of equals): eight independent running maxima (a reduction the
  // compiler vectorises; one running maximum is a dependency chain), then the first cell equal to it.
  auto largest = [&](const float* row) {
    std::array<float, 8> top;
    top.fill(row[0]);
    std::size_t lag = 0;
    for (; lag + 8 <= lags_; lag += 8)
      for (std::size_t j = 0; j < 8; ++j) top[j] = top[j] < row[lag + j] ? row[lag + j] : top[j];
    for (; lag < lags_; ++lag) top[0] = top[0] < row[lag] ? row[lag] : top[0];
    const float m = *std::max_element(top.begin(), top.end());
    return static_cast<std::size_t>(std::find(row, row + lags_, m) - row);
  };
  std::vector<std::size_t>& row_top = s.row_top;
  row_top.resize(bins);

  // Candidate peak on rows normalised by their plain means (the signal raises its row's mean a little).
  double candidate = -1.0;
  std::size_t candidate_lag = 0;
  for (std::size_t d = 0; d < bins; ++d) {
    const float* row = &grid[d * lags_];
    std::array<double, 4> partial{};  // four running sums: vectorised, and no longer one dependency chain
    std::size_t lag = 0;
    for (; lag + 4 <= lags_; lag += 4)
      for (std::size_t j = 0; j < 4; ++j) partial[j] += row[lag + j];
    for (; lag < lags_; ++lag) partial[0] += row[lag];
    const double sum = (partial[0] + partial[1]) + (partial[2] + partial[3]);
    row_noise[d] = sum;
    const double mean = sum / static_cast<double>(lags_);
    const std::size_t top = row_top[d] = largest(row);
    if (row[top] > candidate * mean) {
      candidate = row[top] / mean;
      candidate_lag = top;
    }
  }

  // Noise per Doppler row (a cell-averaging CFAR along the code): the mean of the row's cells away from the
  // candidate's code phase (+-1.5 chips; in every row, which also removes the signal's Doppler side
  // lobes). Per row because real front ends leave narrowband spurs that raise whole rows evenly: one
  // noise level for the whole grid would turn those rows into false alarms.
  const auto guard = std::min(static_cast<std::ptrdiff_t>(std::ceil(1.5 * samples_per_chip_)) + 1,
                              (static_cast<std::ptrdiff_t>(lags_) - 2) / 2);
  const auto lags = static_cast<std::ptrdiff_t>(lags_);
  double best = -1.0;
  int best_bin = 0;
  std::size_t best_lag = 0;
  for (std::size_t d = 0; d < bins; ++d) {
    const float* row = &grid[d * lags_];
    double excluded = 0.0;
    for (std::ptrdiff_t o = -guard; o <= guard; ++o)
      excluded += row[((static_cast<std::ptrdiff_t>(candidate_lag) + o) % lags + lags) % lags];
    row_noise[d] = (row_noise[d] - excluded) / static_cast<double>(lags - (2 * guard + 1));
    const std::size_t top = row_top[d];  // the same cell: the row is divided by one number
    if (row[top] > best * row_noise[d]) {
      best = row[top] / row_noise[d];
      best_bin = static_cast<int>(d);
      best_lag = top;
    }
  }
  const double k = options_.noncoherent;
  const double noise_power = row_noise[static_cast<std::size_t>(best_bin)] / k;  // P_n, one coherent block

  AcquisitionResult result;
  result.prn = prn;
  result.metric = best;
  result.threshold = acquisition_threshold(options_.noncoherent, static_cast<double>(bins * lags_), options_.pfa) / k;
  result.detected = result.metric > result.threshold;

  double doppler = dopplers[static_cast<std::size_t>(best_bin)];
  double lag = static_cast<double>(best_lag);
  double peak_power = best * k * noise_power;
  if (result.detected) {
    // Fine Doppler: step/8 over +-1 coarse step at the peak lag, by rotating the partial sums made once at the
    // coarse Doppler, then a parabola through the best three.
    const double fine = options_.step_hz() / 8.0;
    std::array<double, 17> powers{};
    std::size_t top = 0;
    segment_sums(samples, prn, doppler, lag, s);
    for (std::size_t i = 0; i < powers.size(); ++i) {
      powers[i] = segment_power(s, (static_cast<double>(i) - 8.0) * fine);
      if (powers[i] > powers[top]) top = i;
    }
    double offset = static_cast<double>(top) - 8.0;
    if (top > 0 && top + 1 < powers.size()) {
      const double curvature = powers[top - 1] - 2.0 * powers[top] + powers[top + 1];
      if (curvature < 0.0) offset += 0.5 * (powers[top - 1] - powers[top + 1]) / curvature;
    }
    doppler += offset * fine;

    // Fine code phase: triangle fit through the signal amplitudes (noise power removed) at lag -1, 0, +1.
    auto amplitude = [&](double l) {
      return std::sqrt(std::max(power_at(samples, prn, doppler, l, s) / k - noise_power, 0.0));
    };
    const double before = amplitude(lag - 1.0), centre = amplitude(lag), after = amplitude(lag + 1.0);
    const double drop = centre - std::min(before, after);
    if (drop > 0.0) lag += std::clamp((after - before) / (2.0 * drop), -0.5, 0.5);
    peak_power = power_at(samples, prn, doppler, lag, s);
  }
  const double snr = peak_power / (k * noise_power) - 1.0;  // coherent SNR = C/N0 T_coh
  result.cn0_dbhz = 10.0 * std::log10(std::max(snr, 1e-3) / options_.coherent_s());
  result.doppler_hz = doppler;
  const double chips_per_sample = code_rate_hz(doppler) / options_.fs_hz;
  // The code epoch starts at sample `lag`, so the code phase at sample 0 is -lag chips-per-sample.
  double phase = std::fmod(-lag * chips_per_sample, static_cast<double>(kCodeLength));
  if (phase < 0.0) phase += kCodeLength;
  if (phase >= kCodeLength) phase -= kCodeLength;
  result.code_phase_chips = phase;
  const double period = kCodeLength / chips_per_sample;
  result.code_phase_samples = std::fmod(std::fmod(lag, period) + period, period);
  return result;
}

void Acquisition::check(std::span<const std::complex<float>> samples, int prn) const {
  if (prn < signals::kMinPrn || prn > signals::kMaxPrn)
    throw std::invalid_argument("acquisition: PRN " + std::to_string(prn) + " is not 1..32");
  if (samples.size() < samples_needed())
    throw std::invalid_argument("acquisition: " + std::to_string(samples.size()) + " samples given, " +
                                std::to_string(samples_needed()) + " needed");
}

AcquisitionResult Acquisition::search(std::span<const std::complex<float>> samples, int prn,
                                      std::optional<DopplerWindow> assist) {
  check(samples, prn);
  code_spectrum(prn);
  const std::vector<double> dopplers = doppler_grid(assist);
  return search_grid(samples, prn, dopplers, signal_spectra(samples, dopplers, nullptr), *scratch_[0], nullptr);
}

std::vector<AcquisitionResult> Acquisition::search_each(std::span<const std::complex<float>> samples,
                                                        std::span<const int> prns, WorkerPool* pool) {
  for (int prn : prns) code_spectrum(prn);  // made here, read-only below
  const std::vector<double> dopplers = doppler_grid(std::nullopt);
  // The Doppler-shifted signal spectra (of the grid's rotation bases), shared by every PRN.
  const FftwBuffer* spectra = signal_spectra(samples, dopplers, pool);
  std::vector<AcquisitionResult> results(prns.size());
  spread(pool, static_cast<int>(prns.size()), [&](int i, Scratch& s) {
    results[static_cast<std::size_t>(i)] =
        search_grid(samples, prns[static_cast<std::size_t>(i)], dopplers, spectra, s, nullptr);
  });
  return results;
}

void Acquisition::cancel(std::span<std::complex<float>> samples, const AcquisitionResult& r) const {
  // Least-squares fit of the replica's complex amplitude per millisecond (data bits and the carrier
  // phase stay constant over one code period, near enough), then subtraction.
  const auto& code = signals::ca_code(r.prn);
  const double chips_per_sample = code_rate_hz(r.doppler_hz) / options_.fs_hz;
  const double lag = -r.code_phase_chips / chips_per_sample;  // code phase at sample j: (j - lag) chips/sample
  const std::complex<double> step = std::polar(1.0, kTwoPi * r.doppler_hz / options_.fs_hz);
  const auto segment = static_cast<std::size_t>(std::llround(options_.fs_hz * 1e-3));
  for (std::size_t first = 0; first < samples.size(); first += segment) {
    const std::size_t count = std::min(segment, samples.size() - first);
    const std::complex<double> start =
        std::polar(1.0, kTwoPi * r.doppler_hz * static_cast<double>(first) / options_.fs_hz);
    std::complex<double> replica_phase = start, sum;
    for (std::size_t j = first; j < first + count; ++j) {
      const double chip = chip_at(code, (static_cast<double>(j) - lag) * chips_per_sample);
      sum += std::complex<double>(samples[j]) * std::conj(replica_phase) * chip;
      replica_phase *= step;
    }
    const std::complex<double> amplitude = sum / static_cast<double>(count);
    replica_phase = start;
    for (std::size_t j = first; j < first + count; ++j) {
      const double chip = chip_at(code, (static_cast<double>(j) - lag) * chips_per_sample);
      samples[j] -= std::complex<float>(amplitude * replica_phase * chip);
      replica_phase *= step;
    }
  }
}

std::vector<AcquisitionResult> Acquisition::search(std::span<const std::complex<float>> samples,
                                                   std::span<const int> prns, WorkerPool* pool) {
  for (int prn : prns) check(samples, prn);
  std::vector<AcquisitionResult> results = search_each(samples, prns, pool);
  if (!options_.cancel_cross_correlation) return results;

  // Successive cancellation: confirm detections from the strongest down, each on the samples with the
  // stronger confirmed signals removed, so that their cross-correlations (-21..-24 dB) cannot pass for
  // weak satellites; then search the rest again on the cleaned samples. The threshold is unchanged.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < results.size(); ++i)
    if (results[i].detected) order.push_back(i);
  if (order.empty()) return results;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return results[a].metric > results[b].metric; });
  cleaned_.assign(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(samples_needed()));
  const std::vector<double> dopplers = doppler_grid(std::nullopt);
  for (std::size_t n = 0; n < order.size(); ++n) {
    AcquisitionResult& r = results[order[n]];
    // One PRN at a time (each on the samples the stronger ones were removed from): its rows over the pool.
    if (n > 0) r = search_grid(cleaned_, r.prn, dopplers, signal_spectra(cleaned_, dopplers, pool), *scratch_[0], pool);
    if (r.detected) cancel(cleaned_, r);
  }
  std::vector<int> rest;
  for (const auto& r : results)
    if (std::find(order.begin(), order.end(), static_cast<std::size_t>(&r - results.data())) == order.end())
      rest.push_back(r.prn);
  const std::vector<AcquisitionResult> again = search_each(cleaned_, rest, pool);
  for (const auto& r : again)
    for (auto& slot : results)
      if (slot.prn == r.prn) slot = r;
  return results;
}

}  // namespace ultratrack::receiver
