// SPDX-License-Identifier: GPL-3.0-or-later
// Which Klobuchar ionosphere parameters the receiver applies, and since when. Before subframe 4 page 18
// (broadcast once every 12.5 minutes) a receiver without a navigation file has no broadcast parameters; like
// common receivers it then applies a default set rather than none, and switches to the broadcast (or the
// navigation file's) parameters once it has them.
//
// The default set is RTKLIB's `ion_default` (rtkcmn.c, ionmodel(), marked "2004/1/1": the GPS broadcast of
// 2004-01-01), which RTKLIB uses whenever no broadcast parameters are known:
//   alpha = 0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06   (s, s/semicircle, s/semicircle^2, s/semicircle^3)
//   beta  = 0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07   (s, s/semicircle, s/semicircle^2, s/semicircle^3)
// A mid-activity set: at mid-latitudes it gives a night-time vertical delay of 5 ns (the model's floor) and a
// day-time peak of about 15-20 ns, within roughly 50 % of the broadcast values of most days.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "signals/ephemeris.hpp"

namespace ultratrack::receiver {

enum class IonosphereSource {
  kDefault,         // default_klobuchar()
  kNavigationFile,  // the parameters of a supplied navigation file (hot start)
  kBroadcast,       // decoded from subframe 4 page 18
};

// "default", "nav file", "broadcast".
std::string ionosphere_source_name(IonosphereSource source);

// The RTKLIB default set above, valid.
signals::KlobucharParameters default_klobuchar();

// One switch of the parameters in use: from `since_sample` (receiver sample index; nullopt: from the start).
struct IonosphereModelChange {
  IonosphereSource source = IonosphereSource::kDefault;
  std::optional<std::int64_t> since_sample;
};

// The parameters in use and the history of their sources (for summary.json and the RINEX header).
class IonosphereModel {
 public:
  IonosphereModel();  // the default set, from the start
  const signals::KlobucharParameters& parameters() const { return in_use_; }
  // The supplied or decoded parameters (invalid until either): what a navigation file written by the receiver
  // may carry; the default set is never written as broadcast.
  const signals::KlobucharParameters& known() const { return known_; }
  const std::vector<IonosphereModelChange>& history() const { return history_; }
  // New parameters from `source` at `sample` (nullopt: from the start). Ignored when !params.valid.
  void set(const signals::KlobucharParameters& params, IonosphereSource source, std::optional<std::int64_t> sample);

 private:
  signals::KlobucharParameters in_use_, known_;
  std::vector<IonosphereModelChange> history_;
};

// Seconds of signal from first_sample (the first processed sample) to the change; 0 for one from the start.
double ionosphere_change_seconds(const IonosphereModelChange& change, std::int64_t first_sample, double fs_hz);

// The history as RINEX header COMMENT texts (<= 60 characters each), e.g. "IONO default Klobuchar (RTKLIB
// ion_default) from 0.000 s", then "IONO broadcast Klobuchar from 41.000 s"; applied = false (the PVT's
// correction switched off) gives one line saying so.
std::vector<std::string> ionosphere_comment_lines(const IonosphereModel& model, std::int64_t first_sample, double fs_hz,
                                                  bool applied);

}  // namespace ultratrack::receiver
