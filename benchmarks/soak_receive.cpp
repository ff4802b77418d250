// SPDX-License-Identifier: GPL-3.0-or-later
// Soak run: a long simulation streamed straight into the receiver (no file: an hour at 2.6 MHz would be 19 GB),
// reporting the process's resident memory and the errors as the hours go by, so that a leak, an unbounded buffer
// or a drift of the time tags shows. The built-in nominal constellation, 45 dB-Hz, i8 at 2.6 MHz, hot start.
//   soak_receive [DURATION_S=3600] [REPORT_EVERY_S=600] [scalar|ultra-tight]
// scalar: a static receiver. ultra-tight: the 500 km/h circle (pi/100 rad/s coordinated turn) with the HG1700AE
// IMU at 100 Hz, `receive --coupling ultra-tight`'s defaults (EKF, tight pull-in, alignment from motion). Every
// IMU increment is given to the receiver before the first sample (pipelines::Receiver takes them whole), so the
// IMU series (~60 bytes per 10 ms) is part of the memory from the start and does not grow.
// Prints one line per report: signal time, VmRSS and VmHWM (kB, /proc/self/status), fixes so far, the 3-D error of
// the fixes in the last interval (RMS, max) against the true antenna position at the fix's sample, their time tag
// minus the true GPS time of their sample (max |.|), and for ultra-tight the navigation rows' 3-D error (RMS, max).
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipelines/receive_file.hpp"
#include "pipelines/receiver_pipeline.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation.hpp"

using namespace ultratrack;

namespace {

long status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size());
  return -1;
}

// The simulator's truth rows (ECEF antenna position against receiver time) and the positions waiting for them: a
// fix or a navigation row may come before the truth row after it (the simulator gives a row at the start of the
// block it begins), so each is judged when the truth has passed its time. Rows are kept only that long: the soak's
// own memory must not grow either.
class TruthTrack {
 public:
  struct Stats {
    long count = 0, interval = 0, no_truth = 0;
    double sum2 = 0.0, max_m = 0.0;
    double rms() const { return interval ? std::sqrt(sum2 / static_cast<double>(interval)) : NAN; }
    void next_interval() { sum2 = max_m = 0.0, interval = 0; }
  };

  void add_truth(double t_s, const Eigen::Vector3d& r_e_m) {
    rows_.push_back({t_s, r_e_m});
    while (!pending_.empty() && pending_.front().t_s <= t_s) {
      judge(pending_.front());
      pending_.pop_front();
    }
    while (rows_.size() > 2 && (pending_.empty() ? t_s : pending_.front().t_s) > rows_[1].t_s) rows_.pop_front();
  }
  void add_position(double t_s, const Eigen::Vector3d& r_e_m, Stats& stats) {
    pending_.push_back({t_s, r_e_m, &stats});
    if (!rows_.empty() && rows_.back().t_s >= t_s) {
      judge(pending_.back());
      pending_.pop_back();
    }
  }
  // Positions after the last truth row: counted as without truth.
  void finish() {
    for (const auto& p : pending_) ++p.stats->no_truth;
    pending_.clear();
  }

 private:
  struct Row {
    double t_s;
    Eigen::Vector3d r_e_m;
  };
  struct Pending {
    double t_s;
    Eigen::Vector3d r_e_m;
    Stats* stats;
  };
  void judge(const Pending& p) {
    for (std::size_t k = 1; k < rows_.size(); ++k) {
      if (rows_[k].t_s < p.t_s) continue;
      if (rows_[k - 1].t_s > p.t_s) break;
      const double w = (p.t_s - rows_[k - 1].t_s) / (rows_[k].t_s - rows_[k - 1].t_s);
      const double err = (p.r_e_m - ((1.0 - w) * rows_[k - 1].r_e_m + w * rows_[k].r_e_m)).norm();
      ++p.stats->count, ++p.stats->interval;
      p.stats->sum2 += err * err;
      p.stats->max_m = std::max(p.stats->max_m, err);
      return;
    }
    ++p.stats->no_truth;
  }
  std::deque<Row> rows_;
  std::deque<Pending> pending_;
};

struct SoakObserver final : receiver::ReceiverObserver, pipelines::ReceiveSink {
  TruthTrack truth;
  TruthTrack::Stats fixes, navigation;
  signals::GpsTime start;
  double fs_hz = 0.0;
  double max_tag_s = 0.0;
  void on_fix(const receiver::PvtSolution& f, const receiver::ObservationEpoch& e) override {
    if (!f.valid) return;
    // The true GPS time of the epoch's sample (a perfect receiver clock: sample n is start + n / fs).
    const double true_t = static_cast<double>(e.sample_index) / fs_hz;
    truth.add_position(true_t, f.r_e_m, fixes);
    max_tag_s = std::max(max_tag_s, std::abs(signals::seconds_between(f.time, start) - true_t));
  }
  void on_navigation(const ins::NavState& nav, const pipelines::NavSigma&) override {
    Eigen::Vector3d r_e;
    GeographicLib::Geocentric::WGS84().Forward(nav.lat_rad * 180.0 / M_PI, nav.lon_rad * 180.0 / M_PI, nav.height_m,
                                               r_e.x(), r_e.y(), r_e.z());
    truth.add_position(nav.t_s, r_e, navigation);  // IMU time origin: the first sample, as the simulator writes it
  }
};

struct Streaming final : sim::SimulationSink {
  pipelines::ReceiveOptions options;
  signals::RinexNavData nav;
  SoakObserver* observer = nullptr;
  std::vector<ins::ImuIncrement> imu_rows;
  std::unique_ptr<pipelines::Receiver> receiver;
  std::int64_t next = 0;
  double report_every_s = 600.0, next_report_s = 600.0;

  void imu(const ins::ImuIncrement& increment) override { imu_rows.push_back(increment); }
  void truth(const sim::TruthRow& row) override { observer->truth.add_truth(row.t_s, row.r_e_m); }
  void samples(int antenna, std::span<const std::complex<float>> block) override {
    if (antenna != 0) return;
    if (!receiver) {
      receiver = std::make_unique<pipelines::Receiver>(options, std::move(imu_rows), nav, *observer, *observer);
      imu_rows = {};
    }
    receiver->process(block, next);
    next += static_cast<std::int64_t>(block.size());
    const double t = static_cast<double>(next) / options.receiver.fs_hz;
    if (t + 1e-9 < next_report_s) return;
    auto& f = observer->fixes;
    auto& n = observer->navigation;
    std::printf(
        "%7.0f s  VmRSS %7ld kB  VmHWM %7ld kB  fixes %6ld  3-D error RMS %.2f m max %.2f m  |time tag - truth| max "
        "%.1f ns",
        t, status_kb("VmRSS:"), status_kb("VmHWM:"), f.count, f.rms(), f.max_m, observer->max_tag_s * 1e9);
    if (options.coupling == pipelines::Coupling::kUltraTight)
      std::printf("  nav rows %8ld  3-D error RMS %.2f m max %.2f m", n.count, n.rms(), n.max_m);
    std::printf("\n");
    std::fflush(stdout);
    f.next_interval();
    n.next_interval();
    observer->max_tag_s = 0.0;
    next_report_s += report_every_s;
  }
};

}  // namespace

int main(int argc, char** argv) {
  sim::Scenario scenario;  // nominal constellation, 45 dB-Hz, i8 at 2.6 MHz, ionosphere on
  scenario.duration_s = argc > 1 ? std::atof(argv[1]) : 3600.0;
  const double report_every_s = argc > 2 ? std::atof(argv[2]) : 600.0;
  const std::string coupling = argc > 3 ? argv[3] : "scalar";
  if (!(scenario.duration_s > 0.0) || !(report_every_s > 0.0) || (coupling != "scalar" && coupling != "ultra-tight")) {
    std::fprintf(stderr, "usage: soak_receive [DURATION_S=3600] [REPORT_EVERY_S=600] [scalar|ultra-tight]\n");
    return 2;
  }
  scenario.tow_s = 518398.0;
  Streaming stream;
  stream.options.receiver.fs_hz = scenario.sample_rate_hz;
  stream.options.receiver.pvt.troposphere = scenario.troposphere;
  if (coupling == "ultra-tight") {
    scenario.llh_deg_m[2] = 1000.0;
    scenario.trajectory_profile = "circle";
    scenario.trajectory_duration_s = scenario.duration_s;
    scenario.imu_preset = "hg1700ae";
    scenario.imu_seed = 7;
    stream.options.coupling = pipelines::Coupling::kUltraTight;
  }
  stream.nav = sim::to_rinex_nav(sim::load_navigation(scenario));
  pipelines::date_recording(stream.options.receiver, stream.nav, scenario.gps_week);
  if (std::string why; !stream.options.IsValid(&why)) {
    std::fprintf(stderr, "soak_receive: %s\n", why.c_str());
    return 2;
  }

  SoakObserver observer;
  observer.start = {scenario.gps_week, scenario.tow_s};
  observer.fs_hz = scenario.sample_rate_hz;
  stream.observer = &observer;
  stream.report_every_s = stream.next_report_s = report_every_s;
  std::printf("soak: %.0f s of the nominal constellation at %.1f MHz streamed into receive (%s, hot start%s)\n",
              scenario.duration_s, scenario.sample_rate_hz / 1e6, coupling.c_str(),
              coupling == "ultra-tight" ? ", 500 km/h circle, HG1700AE" : ", static");
  sim::simulate(scenario, stream);
  if (!stream.receiver) {
    std::fprintf(stderr, "soak_receive: no samples were simulated\n");
    return 1;
  }
  const pipelines::ReceiveSummary summary = stream.receiver->finish();
  observer.truth.finish();
  std::printf(
      "end: %ld fixes (%ld without truth), %ld navigation rows (%ld without truth); handed over %s; VmHWM %ld kB\n",
      observer.fixes.count, observer.fixes.no_truth, observer.navigation.count, observer.navigation.no_truth,
      summary.handed_over ? "yes" : "no", status_kb("VmHWM:"));
  for (const auto& line : summary.report) std::printf("  %s\n", line.c_str());
  const bool ok =
      observer.fixes.count > 0 && (coupling == "scalar" || (summary.handed_over && observer.navigation.count > 0));
  return ok ? 0 : 1;
}
