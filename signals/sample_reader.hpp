// SPDX-License-Identifier: GPL-3.0-or-later
// Streaming reader of IF sample files (formats in sample_format.hpp). Samples come out as complex float
// in the file's own scale (real formats give imag = 0); IF removal, I/Q swap and Q negation belong to
// the receiver's SampleSource. The whole-file checks happen at open: a missing or empty file, or a size
// that is not a whole number of samples (a truncated final sample), is an InputError naming the file.
// Packed 2-bit formats come out as their levels (-3, -1, +1, +3); any start sample works, also one inside
// a byte (the rest of that byte is kept for the next read).
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

class SampleReader {
 public:
  // start_sample: samples to skip at the start of the file (an InputError when beyond its end).
  // layout: how the 2-bit formats are packed (ignored by the others).
  SampleReader(std::filesystem::path path, SampleFormat format, std::int64_t start_sample = 0,
               TwoBitLayout layout = {});

  // Reads up to out.size() samples into out; returns how many were read (0 at the end of the file).
  std::size_t read(std::span<std::complex<float>> out);

  std::int64_t total_samples() const { return total_samples_; }
  std::int64_t position() const { return position_; }  // index of the next sample to be read
  SampleFormat format() const { return format_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  SampleFormat format_;
  std::ifstream file_;
  std::int64_t total_samples_ = 0;
  std::int64_t position_ = 0;
  std::vector<char> raw_;  // reused between reads
  // Packed formats: the levels of the samples of each byte value in file order, and what is left of a byte
  // that a read (or the start sample) cut.
  std::array<std::array<float, 4>, 256> levels_{};
  std::size_t per_byte_ = 0;
  std::array<std::complex<float>, 4> carry_{};
  std::size_t carry_begin_ = 0, carry_end_ = 0;

  void open_packed(std::uintmax_t size, std::int64_t start_sample, TwoBitLayout layout);
  std::size_t read_packed(std::span<std::complex<float>> out);
  // The samples of byte b from the k-th on, appended to out from index n; returns the new n.
  std::size_t unpack(unsigned char b, std::size_t k, std::size_t k_end, std::span<std::complex<float>> out,
                     std::size_t n) const;
};

}  // namespace ultratrack::signals
