// SPDX-License-Identifier: GPL-3.0-or-later
// The sample source of a multi-antenna receiver: one IF file per antenna, recorded on one clock, read
// sample-synchronously (the same sample indices from every file) and converted to complex baseband by one
// SampleSource each (same format, rate, IF and fix-ups). Files of different lengths are an InputError: they
// cannot be sample-synchronous. Units: samples, Hz.
#pragma once

#include <complex>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "receiver/sample_source.hpp"

namespace ultratrack::receiver {

class MultiSampleSource {
 public:
  // Throws signals::InputError naming the file: unreadable, bad options, or a length that differs from the
  // first file's (in samples of `format`; a trailing partial sample is the reader's own error).
  MultiSampleSource(const std::vector<std::filesystem::path>& paths, signals::SampleFormat format,
                    const SampleSourceOptions& options);
  ~MultiSampleSource();

  int num_antennas() const { return static_cast<int>(sources_.size()); }
  // Fills up to out[a].size() samples of every antenna a (all spans the same size); the same count from each.
  SampleBlock read(std::span<const std::span<std::complex<float>>> out);
  std::int64_t total_samples() const { return sources_.front()->total_samples(); }
  const SampleSource& antenna(int a) const { return *sources_[static_cast<std::size_t>(a)]; }

 private:
  std::vector<std::unique_ptr<SampleSource>> sources_;
};

}  // namespace ultratrack::receiver
