// Writes IF sample files (formats in sample_format.hpp) from complex float samples, already scaled to
// the format's integer range by the caller (values are rounded and saturated; real formats keep only
// the real part). The file is written under a temporary name and renamed by finish(): an unfinished
// writer leaves no file behind.
#pragma once

#include <complex>
#include <filesystem>
#include <fstream>
#include <span>
#include <vector>

#include "signals/sample_format.hpp"

namespace ultratrack::signals {

class SampleWriter {
 public:
  SampleWriter(std::filesystem::path path, SampleFormat format);
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
};

}  // namespace ultratrack::signals
