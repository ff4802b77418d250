// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's source of complex baseband samples: reads an IF file (signals::SampleReader) and
// removes the intermediate frequency, so that every later stage sees a signal centred at 0 Hz with
// Doppler as the only carrier offset. This is the one place IF handling lives. Units: Hz, samples.
//
// Conversion of one sample x (complex as read; real formats give x + j0), in this order:
//   1. complex formats: --iq-swap exchanges I and Q, then --q-negate negates Q (conjugates x);
//   2. IF removal: y = x * exp(-j 2 pi if_hz n / fs_hz), n the absolute sample counter (from the start of
//      the file), with a phase-continuous NCO: blocks of any size give the same output as one block;
//   3. real formats: --q-negate conjugates y, which undoes a spectrum inverted by a high-side local
//      oscillator (the same as a negative if_hz); --iq-swap is meaningless for real samples (rejected).
// No low-pass filter and no decimation: a real input at IF becomes s/2 at 0 Hz plus its image s*/2 at
// -2 IF (at fs/4 sampling exactly at the Nyquist frequency), which the code correlators reject because
// it sits far outside the Doppler range; the output keeps the file's rate so code timing is unchanged.
#pragma once

#include <complex>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "signals/sample_format.hpp"
#include "signals/sample_reader.hpp"

namespace ultratrack::receiver {

struct SampleSourceOptions {
  double fs_hz = 0.0;    // sample rate, > 0
  double if_hz = 0.0;    // intermediate frequency, |if_hz| < fs_hz / 2; 0 for complex baseband
  bool iq_swap = false;  // complex formats only
  bool q_negate = false;
  std::int64_t start_sample = 0;  // samples of the file to skip; the counter still counts from the file start
  double int16_gain = 0.0;        // file scale -> int16 output; 0: automatic (see SampleSource::int16_gain)
  signals::TwoBitLayout two_bit;  // packing of the 2-bit formats (r2, i2)

  // False with a reason when the options cannot describe a recording of `format`.
  bool IsValid(signals::SampleFormat format, std::string* error) const;
};

// IF removal and I/Q fix-ups on blocks already in memory (the pure part of SampleSource, usable on
// synthesised samples). Successive calls continue the NCO phase from the sample counter.
class BasebandConverter {
 public:
  BasebandConverter(const SampleSourceOptions& options, bool complex_input);
  // Converts samples in place; the first one has counter next_sample(). Allocates nothing.
  void convert(std::span<std::complex<float>> samples);
  std::int64_t next_sample() const { return next_sample_; }

 private:
  double if_cycles_per_sample_;
  double phase_cycles_;  // NCO phase at next_sample_, in [0, 1)
  std::int64_t next_sample_;
  bool complex_input_, iq_swap_, q_negate_;
};

// Where a block sits on the receiver's clock: the counter of its first sample and how many samples came.
struct SampleBlock {
  std::int64_t first_sample = 0;
  std::size_t count = 0;  // 0 at the end of the file
};

class SampleSource {
 public:
  // Throws signals::InputError (naming the file) for bad options or an unreadable file.
  SampleSource(std::filesystem::path path, signals::SampleFormat format, const SampleSourceOptions& options);

  // Fills up to out.size() baseband samples (fewer only at the end of the file).
  SampleBlock read(std::span<std::complex<float>> out);
  // The same as int16 I/Q: baseband samples times int16_gain(), rounded and saturated.
  SampleBlock read(std::span<std::complex<std::int16_t>> out);

  // Gain from the file's sample scale to the int16 output, options.int16_gain when given. Automatic:
  // i8/r8 64 and i16/r16 1/4 (full scale to ~11500, headroom for the sqrt(2) growth of the mixing
  // rotation); r2/i2 1024 (levels +-1, +-3: RMS ~1900 at the 1-sigma threshold, as i8 at full scale / 4); f32, which
  // has no full scale, 2048 / RMS of the first 2^16 samples (Gaussian peaks at 6 sigma stay below 32767; quantisation
  // noise is 66 dB below the input noise; 1 for an all-zero head).
  float int16_gain() const { return int16_gain_; }
  std::int64_t next_sample() const { return converter_.next_sample(); }
  std::int64_t total_samples() const { return reader_.total_samples(); }
  const SampleSourceOptions& options() const { return options_; }
  signals::SampleFormat format() const { return reader_.format(); }
  const std::filesystem::path& path() const { return reader_.path(); }

 private:
  SampleSourceOptions options_;
  signals::SampleReader reader_;
  BasebandConverter converter_;
  float int16_gain_;
  std::vector<std::complex<float>> scratch_;  // for int16 output, grown once to the largest block
};

}  // namespace ultratrack::receiver
