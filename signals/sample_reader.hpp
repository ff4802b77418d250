// Streaming reader of IF sample files (formats in sample_format.hpp). Samples come out as complex float
// in the file's own scale (real formats give imag = 0); IF removal, I/Q swap and Q negation belong to
// the receiver's SampleSource. The whole-file checks happen at open: a missing or empty file, or a size
// that is not a whole number of samples (a truncated final sample), is an InputError naming the file.
#pragma once

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
  SampleReader(std::filesystem::path path, SampleFormat format, std::int64_t start_sample = 0);

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
};

}  // namespace ultratrack::signals
