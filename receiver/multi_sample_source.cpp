// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/multi_sample_source.hpp"

#include <fmt/core.h>

#include <stdexcept>

#include "signals/input_error.hpp"

namespace ultratrack::receiver {

MultiSampleSource::MultiSampleSource(const std::vector<std::filesystem::path>& paths, signals::SampleFormat format,
                                     const SampleSourceOptions& options) {
  if (paths.empty()) throw signals::InputError("command line", "no input file");
  for (const auto& p : paths) {
    sources_.push_back(std::make_unique<SampleSource>(p, format, options));
    const SampleSource& s = *sources_.back();
    const SampleSource& first = *sources_.front();
    if (s.total_samples() != first.total_samples())
      throw signals::InputError(
          p.string(),
          fmt::format("holds {} samples of {} but {} holds {}: the antenna files must be recorded "
                      "sample-synchronously (same format, same length)",
                      s.total_samples(), signals::to_string(format), first.path().string(), first.total_samples()));
  }
}

MultiSampleSource::~MultiSampleSource() = default;

SampleBlock MultiSampleSource::read(std::span<const std::span<std::complex<float>>> out) {
  if (out.size() != sources_.size()) throw std::invalid_argument("MultiSampleSource: one span per antenna");
  SampleBlock first;
  for (std::size_t a = 0; a < sources_.size(); ++a) {
    if (out[a].size() != out[0].size()) throw std::invalid_argument("MultiSampleSource: spans differ in size");
    const SampleBlock b = sources_[a]->read(out[a]);
    if (a == 0) first = b;
    // Equal lengths and one start offset: every file gives the same block (a failed read is the reader's error).
    if (b.first_sample != first.first_sample || b.count != first.count)
      throw signals::InputError(sources_[a]->path().string(), "lost sample synchronisation with the master file");
  }
  return first;
}

}  // namespace ultratrack::receiver
