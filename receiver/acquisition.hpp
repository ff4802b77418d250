// SPDX-License-Identifier: GPL-3.0-or-later
// GPS L1 C/A acquisition: parallel code-phase search (FFT circular correlation, FFTW single precision)
// over a Doppler grid, K coherent blocks of T_coh = 1..10 ms summed non-coherently, a detection
// threshold from a false-alarm probability, then refinement of Doppler and code phase and a C/N0
// estimate. Input: complex baseband samples (receiver/sample_source.hpp). Units: Hz, chips, samples, dB-Hz.
//
// Test statistic and threshold. Per cell (Doppler bin d, code lag n) Z = sum_k |Y_k|^2 / P_n, Y_k the
// coherent correlation of block k and P_n = E|Y|^2 under noise alone (estimated as the mean of the
// cells of the same Doppler row away from the peak's code phase, divided by K: a cell-averaging CFAR along
// the code, robust to narrowband spurs that raise whole rows; its error, 1/sqrt(K x lags) with 1e3..4e4
// lags per row, moves the false-alarm rate by a few per cent).
// For complex circular Gaussian noise each |Y_k|^2 / P_n is exponential(1) (chi-square with 2 dof, / 2),
// so under noise Z ~ Gamma(K, 1) (chi-square with 2K dof, / 2), whose tail is
//     Q(K, g) = P(Z > g) = exp(-g) sum_{i=0}^{K-1} g^i / i!.
// Searching M = (Doppler bins) x (code lags in one code period) cells and declaring a detection when
// max Z > g, the false-alarm probability per PRN search is 1 - (1 - Q(K, g))^M; we solve
//     Q(K, g) = 1 - (1 - pfa)^(1/M)
// for g. Cells are treated as independent; oversampling (several samples per chip) and Doppler steps
// narrower than 1/T_coh make neighbours correlated, which pushes the real rate below pfa, while the
// estimated noise level (finite cells, the peak's own lags excluded) pushes it up by ~10 %. Measured on
// white noise (tests): 38 and 50 false alarms where 38.4 +- 6.1 were expected (K = 1, 4; 1 sample/chip),
// 14 where 9.6 +- 3.1 (4 MHz, K = 2). Strong satellites' cross-correlations are not noise: they can lift
// an absent PRN over g (real recordings: see tests/receiver/acquisition_real_data_test.cpp).
// metric and threshold are reported as Z / K (peak power over mean noise power).
//
// Data bits: the 50 bit/s LNAV data flips the sign at most once per 20 ms. For T_coh > 1 ms a block that
// holds a flip loses coherent power (at worst all of it, on average 2/3 of it when it holds one); we
// accept that loss: with T_coh <= 10 ms at most every second block holds a bit edge and the
// non-coherent sum over K blocks keeps the others, so the average loss is <= 10*log10(1 - 1/6) = 0.8 dB.
//
// Folding: when a code period is a whole number P of samples (2.6, 4, 12, 38.192 MHz, ...), each Doppler-
// wiped block is summed period by period into P samples before the FFT, which gives exactly the same
// circular correlation with a one-period replica: FFTs of P points for any T_coh (10x cheaper at 10 ms).
//
// Doppler bins by rotation: wiping off f + q fs/F instead of f multiplies the (folded) block by
// exp(-j 2 pi q n / F), which shifts its F-point DFT by q bins exactly. When the grid step divides fs/F (1 kHz
// when folded; the receiver's 4 ms grid has 6 steps per kHz), only the first R = fs / (F step) bins of a grid
// need a carrier wipe-off and a forward FFT; every other bin reads one of those spectra q bins further on.
//
// Code Doppler: block k is aligned on the code drift f_d / f_L1 before the non-coherent sum, so long
// sums (K T_coh up to seconds) do not smear the peak. Refinement, coarse to fine: the samples of the peak's
// code phase are code- and carrier-wiped once (at the coarse Doppler) into 0.1 ms partial sums; the fine
// Doppler search (step/8 over +-1 coarse step) rotates those sums instead of correlating the samples again
// for every trial Doppler (the residual rotation inside one 0.1 ms sum is at most 0.0084 cycles: a power
// change below 1e-3, the same on both sides of the peak), then a parabola through the best three; the code
// phase by a triangle fit through the three lags around the peak, correlated exactly at the refined Doppler;
// C/N0 = (Z*/K - 1) / T_coh from the refined peak Z*.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "receiver/fftw_plan.hpp"
#include "receiver/worker_pool.hpp"

namespace ultratrack::receiver {

struct AcquisitionOptions {
  double fs_hz = 0.0;              // sample rate of the baseband samples, >= 1.023 MHz
  int coherent_ms = 1;             // T_coh in ms, 1..10
  int noncoherent = 1;             // K blocks summed non-coherently, 1..1000
  double doppler_max_hz = 5000.0;  // search +-doppler_max_hz (unassisted), > 0, <= fs/4
  double doppler_step_hz = 0.0;    // 0: 2 / (3 T_coh); otherwise (0, 1 / T_coh]
  double pfa = 1e-3;               // false-alarm probability of one PRN search, (0, 0.5]
  // Multi-PRN searches: confirm detections strongest first with the stronger signals cancelled, so that
  // Gold-code cross-correlations of strong satellites are not reported as weak ones (about 2x the time).
  bool cancel_cross_correlation = true;

  double coherent_s() const { return coherent_ms * 1e-3; }
  double step_hz() const { return doppler_step_hz > 0.0 ? doppler_step_hz : 2.0 / (3.0 * coherent_s()); }
  bool IsValid(std::string* error) const;
};

// An assisted search: only Doppler within center_hz +- half_width_hz (the grid keeps the same step).
struct DopplerWindow {
  double center_hz = 0.0;
  double half_width_hz = 0.0;
};

struct AcquisitionResult {
  int prn = 0;
  bool detected = false;
  double doppler_hz = 0.0;          // carrier Doppler of the baseband signal (refined)
  double code_phase_chips = 0.0;    // code phase at the first searched sample, [0, 1023)
  double code_phase_samples = 0.0;  // samples from the first searched sample to the next code epoch
  double cn0_dbhz = 0.0;            // from the refined peak; meaningful when detected
  double metric = 0.0;              // peak / mean noise power over the grid, Z / K
  double threshold = 0.0;           // metric threshold for pfa, Z / K units
};

// The detection threshold g (in Z units, Gamma(K, 1) tail) for pfa over `cells` independent cells.
double acquisition_threshold(int noncoherent, double cells, double pfa);

// One acquisition engine for a sample rate and search shape: FFT plans, buffers and the code spectra
// (per PRN, made on first use and cached) live as long as the object, so the receiver can call it again
// on later blocks (re-acquisition) without planning or allocating. Not thread-safe: one per thread.
class Acquisition {
 public:
  // Throws std::invalid_argument when !options.IsValid().
  explicit Acquisition(const AcquisitionOptions& options);

  const AcquisitionOptions& options() const { return options_; }
  // Samples one search reads: K * T_coh of signal.
  std::size_t samples_needed() const { return static_cast<std::size_t>(options_.noncoherent) * block_size_; }
  std::size_t block_size() const { return block_size_; }  // samples per coherent block
  // Cells of one unassisted search (for the threshold).
  double cells() const;

  // Searches one PRN (1..32) in samples[0 .. samples_needed()); samples[0] is the sample whose code
  // phase is reported. Throws std::invalid_argument for a bad PRN or too few samples.
  AcquisitionResult search(std::span<const std::complex<float>> samples, int prn,
                           std::optional<DopplerWindow> assist = std::nullopt);
  // Searches several PRNs over the same samples; the Doppler-shifted signal spectra are shared between
  // them (cached when they fit in memory_budget_bytes). With options.cancel_cross_correlation, detections
  // are confirmed by successive cancellation (see AcquisitionOptions) and the rest searched again.
  // With a pool, the signal spectra and the PRNs are spread over its threads (one scratch set per thread,
  // made on first use); each PRN's result is the same whatever the number of threads. The pool must be idle
  // (no parallel_for running, this call not inside one of its jobs or tasks).
  std::vector<AcquisitionResult> search(std::span<const std::complex<float>> samples, std::span<const int> prns,
                                        WorkerPool* pool = nullptr);

 private:
  // Buffers one search works in: one set per thread of a parallel search.
  struct Scratch {
    explicit Scratch(std::size_t fft_size, std::size_t lags);
    FftwBuffer mixed, product, correlation, spectrum;
    std::vector<float> grid;                      // all rows [bin * lags + lag]
    std::vector<double> row_noise;                // row sums, then noise cell mean per Doppler row
    std::vector<std::size_t> row_top;             // lag of each row's largest cell
    std::vector<double> segment_re, segment_im;   // 0.1 ms partial sums of one code phase [block * segments + j]
    std::array<float, 256> base_re{}, base_im{};  // carrier wipe-off phasors of one chunk
  };
  const FftwBuffer& code_spectrum(int prn);
  // Calls f(i, scratch) for i in [0, n), spread over the pool's threads when there is one.
  template <class F>
  void spread(WorkerPool* pool, int n, F&& f);
  void doppler_spectrum(std::span<const std::complex<float>> samples, int block, double doppler_hz, FftwBuffer& out,
                        Scratch& s) const;
  // Signal spectra of a grid's rotation bases ([base * K + k] in spectrum_cache_), spread over the pool;
  // nullptr when they do not fit in memory_budget_bytes_ (then each bin wipes and transforms its own).
  const FftwBuffer* signal_spectra(std::span<const std::complex<float>> samples, const std::vector<double>& dopplers,
                                   WorkerPool* pool);
  // Writes the non-coherent sum over lags of one Doppler bin to acc[0 .. lags); spectra: the K spectra of the
  // bin's rotation base and shift its distance from it in FFT bins (nullptr: made here).
  void correlate_bin(std::span<const std::complex<float>> samples, const FftwBuffer* spectra, std::size_t shift,
                     int prn, double doppler_hz, float* acc, Scratch& s) const;
  // s.segment_re/im: code- and carrier-wiped partial sums at one Doppler and lag (see the file comment).
  void segment_sums(std::span<const std::complex<float>> samples, int prn, double doppler_hz, double lag_samples,
                    Scratch& s) const;
  // Non-coherent power of the partial sums with the carrier moved by offset_hz.
  double segment_power(const Scratch& s, double offset_hz) const;
  double power_at(std::span<const std::complex<float>> samples, int prn, double doppler_hz, double lag_samples,
                  Scratch& s) const;
  // The grid's rows are spread over the pool when one is given (the search's result does not depend on it).
  AcquisitionResult search_grid(std::span<const std::complex<float>> samples, int prn,
                                const std::vector<double>& dopplers, const FftwBuffer* spectra, Scratch& s,
                                WorkerPool* pool);
  std::vector<double> doppler_grid(std::optional<DopplerWindow> assist) const;
  void check(std::span<const std::complex<float>> samples, int prn) const;
  std::vector<AcquisitionResult> search_each(std::span<const std::complex<float>> samples, std::span<const int> prns,
                                             WorkerPool* pool);
  // Removes a detected signal from samples (amplitude fitted per millisecond).
  void cancel(std::span<std::complex<float>> samples, const AcquisitionResult& result) const;

  AcquisitionOptions options_;
  std::size_t block_size_;  // N = round(fs T_coh)
  std::size_t fft_size_;    // F: one code period when it is a whole number of samples (folding), else N
  std::size_t lags_;        // code lags searched: one code period, min(N, ceil(1023 fs / f_chip))
  double samples_per_chip_;
  std::size_t rotation_;  // R: grid bins per FFT bin (fs / (F step)) when whole, else 0 (no rotation)
  std::size_t segment_;   // samples per partial sum of the fine search (0.1 ms)
  FftwPlan forward_, backward_;
  std::vector<std::unique_ptr<Scratch>> scratch_;        // [0] always; more for parallel searches
  std::vector<std::optional<FftwBuffer>> code_spectra_;  // index prn - 1
  std::vector<FftwBuffer> spectrum_cache_;               // [base * K + k] of the grid being searched
  std::vector<std::complex<float>> cleaned_;             // samples with confirmed signals cancelled
  std::size_t memory_budget_bytes_ = std::size_t{256} << 20;
};

}  // namespace ultratrack::receiver
