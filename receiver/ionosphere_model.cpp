// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/ionosphere_model.hpp"

#include <fmt/format.h>

namespace ultratrack::receiver {

std::string ionosphere_source_name(IonosphereSource source) {
  switch (source) {
    case IonosphereSource::kDefault:
      return "default";
    case IonosphereSource::kNavigationFile:
      return "nav file";
    case IonosphereSource::kBroadcast:
      return "broadcast";
  }
  return "unknown";
}

signals::KlobucharParameters default_klobuchar() {
  signals::KlobucharParameters p;
  const double alpha[4] = {0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06};
  const double beta[4] = {0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07};
  for (int i = 0; i < 4; ++i) {
    p.alpha[i] = alpha[i];
    p.beta[i] = beta[i];
  }
  p.valid = true;
  return p;
}

IonosphereModel::IonosphereModel()
    : in_use_(default_klobuchar()), history_{{IonosphereSource::kDefault, std::nullopt}} {}

void IonosphereModel::set(const signals::KlobucharParameters& params, IonosphereSource source,
                          std::optional<std::int64_t> sample) {
  if (!params.valid) return;
  in_use_ = params;
  known_ = params;
  if (history_.back().source == source) return;
  // A source given from the start replaces the default rather than following it.
  if (!sample && history_.size() == 1) history_.clear();
  history_.push_back({source, sample});
}

double ionosphere_change_seconds(const IonosphereModelChange& change, std::int64_t first_sample, double fs_hz) {
  if (!change.since_sample || fs_hz <= 0.0) return 0.0;
  return static_cast<double>(*change.since_sample - first_sample) / fs_hz;
}

std::vector<std::string> ionosphere_comment_lines(const IonosphereModel& model, std::int64_t first_sample, double fs_hz,
                                                  bool applied) {
  if (!applied) return {"IONO none applied (--ionosphere off)"};
  std::vector<std::string> lines;
  for (const IonosphereModelChange& c : model.history())
    lines.push_back(fmt::format("IONO {} Klobuchar{} from {:.3f} s", ionosphere_source_name(c.source),
                                c.source == IonosphereSource::kDefault ? " (RTKLIB ion_default)" : "",
                                ionosphere_change_seconds(c, first_sample, fs_hz)));
  return lines;
}

}  // namespace ultratrack::receiver
