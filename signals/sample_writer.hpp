// SPDX-License-Identifier: GPL-3.0-or-later
// Writes IF sample files (formats in sample_format.hpp) from complex float samples, already scaled to
// the format's integer range by the caller (values are rounded and saturated; real formats keep only
// the real part). The file is written under a temporary name and renamed by finish(): an unfinished
// writer leaves no file behind.
// 2-bit formats (r2, i2): each component x is quantised to -3, -1, +1, +3 with thresholds at -2, 0, +2
// (nearest level, saturating), so an input whose noise sigma is 2 (signals::nominal_rms) has the 1-sigma
// threshold of minimum loss: the SNR after an ideal 2-bit quantiser with levels 1 and 3 and threshold 1 sigma
// is 0.881 of the input's, a 0.55 dB loss (Gaussian noise, samples independent). A final byte that is not
// full is completed with +1 samples (at most 3 real or 1 complex, at the end of the file).
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <vector>

#include "signals/sample_format.hpp"

namespace ultratrack::signals {

class SampleWriter {
 public:
  // layout: how the 2-bit formats are packed (ignored by the others).
  SampleWriter(std::filesystem::path path, SampleFormat format, TwoBitLayout layout = {});
  ~SampleWriter();  // removes the temporary file when finish() was not called
  SampleWriter(const SampleWriter&) = delete;
  SampleWriter& operator=(const SampleWriter&) = delete;

  void write(std::span<const std::complex<float>> samples);
  // Flushes, closes and renames the temporary file to its final name. Throws on I/O failure.
  void finish();

 private:
  std::filesystem::path path_, temp_path_;
  SampleFormat format_;
  std::ofstream file_;
  std::vector<char> raw_;
  bool finished_ = false;
  // 2-bit formats: the code of each level (-3, -1, +1, +3), field positions in file order, the byte being
  // filled and how many of its fields are set.
  std::array<std::uint8_t, 4> code_{};
  std::array<int, 4> shift_{};
  std::uint8_t pending_ = 0;
  int pending_fields_ = 0;

  void pack(float x, char*& p);
};

}  // namespace ultratrack::signals
