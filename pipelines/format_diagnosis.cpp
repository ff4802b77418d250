// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/format_diagnosis.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <complex>
#include <numeric>

#include "receiver/acquisition.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr int kMinimumSatellites = 4, kMargin = 3;

struct Detections {
  std::vector<int> prns;
  double metric_sum = 0.0;  // of the detections' peak / noise: orders layouts that detect as many satellites
};

// The PRNs detected in the first 10 ms with `options`, or nothing when the file is shorter.
Detections detect(const std::filesystem::path& input, signals::SampleFormat format,
                  const receiver::SampleSourceOptions& options, receiver::Acquisition& acquisition) {
  receiver::SampleSource source(input, format, options);
  std::vector<std::complex<float>> samples(acquisition.samples_needed());
  if (source.read(samples).count != samples.size()) return {};
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  Detections d;
  for (const auto& r : acquisition.search(samples, prns))
    if (r.detected) {
      d.prns.push_back(r.prn);
      d.metric_sum += r.metric;
    }
  return d;
}

}  // namespace

FormatDiagnosis diagnose_sample_format(const std::filesystem::path& input, signals::SampleFormat format,
                                       const receiver::SampleSourceOptions& options) {
  FormatDiagnosis d;
  if (!signals::is_two_bit(format)) return d;
  receiver::AcquisitionOptions a;
  a.fs_hz = options.fs_hz;
  a.coherent_ms = 1;
  a.noncoherent = 10;
  a.pfa = 1e-3;
  if (!a.IsValid(nullptr)) return d;
  receiver::Acquisition acquisition(a);
  d.detected_as_given = static_cast<int>(detect(input, format, options, acquisition).prns.size());
  Detections best;
  for (const auto coding : {signals::TwoBitCoding::twos_complement, signals::TwoBitCoding::sign_magnitude,
                            signals::TwoBitCoding::offset_binary, signals::TwoBitCoding::nt1065})
    for (const auto order : {signals::BitOrder::lsb_first, signals::BitOrder::msb_first}) {
      if (coding == options.two_bit.coding && order == options.two_bit.order) continue;
      receiver::SampleSourceOptions other = options;
      other.two_bit = {coding, order};
      const Detections found = detect(input, format, other, acquisition);
      const int n = static_cast<int>(found.prns.size());
      const bool better_than_best = found.prns.size() > best.prns.size() ||
                                    (found.prns.size() == best.prns.size() && found.metric_sum > best.metric_sum);
      if (better_than_best && n >= kMinimumSatellites && n >= d.detected_as_given + kMargin) {
        best = found;
        d.better_prns = found.prns;
        d.better_flags =
            fmt::format("--2bit-coding {} --2bit-order {}", signals::to_string(coding), signals::to_string(order));
      }
    }
  return d;
}

std::string to_sentence(const FormatDiagnosis& d) {
  if (d.better_flags.empty()) return {};
  return fmt::format(" With {} the first 10 ms show {} satellites (PRNs {}) against {} as given.", d.better_flags,
                     d.better_prns.size(), fmt::join(d.better_prns, ", "), d.detected_as_given);
}

}  // namespace ultratrack::pipelines
