// SPDX-License-Identifier: GPL-3.0-or-later
// Soak run (issue 21): a long static simulation streamed straight into the receiver (no file: an hour at 2.6 MHz
// would be 19 GB), reporting the process's resident memory and the fixes' errors as the hours go by, so that a
// leak, an unbounded buffer or a drift of the time tags shows. The built-in nominal constellation, 45 dB-Hz, hot
// start, scalar tracking.
//   soak_receive [DURATION_S=3600] [REPORT_EVERY_S=600]
// Prints one line per report: signal time, VmRSS and VmHWM (kB, /proc/self/status), fixes so far, the 3-D error of
// the fixes in the last interval (RMS, max) and their time tag minus the true GPS time of their sample (max |.|).
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

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

struct FixErrors final : receiver::ReceiverObserver {
  Eigen::Vector3d truth_e;
  signals::GpsTime start;
  double fs_hz = 0.0;
  long fixes = 0;
  double sum2 = 0.0, max_m = 0.0, max_tag_s = 0.0;
  long interval_fixes = 0;
  void on_fix(const receiver::PvtSolution& f, const receiver::ObservationEpoch& e) override {
    if (!f.valid) return;
    ++fixes, ++interval_fixes;
    const double err = (f.r_e_m - truth_e).norm();
    sum2 += err * err;
    max_m = std::max(max_m, err);
    // The true GPS time of the epoch's sample (a perfect receiver clock: sample n is start + n / fs).
    const double true_t = static_cast<double>(e.sample_index) / fs_hz;
    max_tag_s = std::max(max_tag_s, std::abs(signals::seconds_between(f.time, start) - true_t));
  }
};

struct Streaming final : sim::SimulationSink {
  pipelines::Receiver* receiver = nullptr;
  FixErrors* fixes = nullptr;
  std::int64_t next = 0;
  double fs = 0.0, report_every_s = 600.0, next_report_s = 600.0;
  void samples(int antenna, std::span<const std::complex<float>> block) override {
    if (antenna != 0) return;
    receiver->process(block, next);
    next += static_cast<std::int64_t>(block.size());
    const double t = static_cast<double>(next) / fs;
    if (t + 1e-9 >= next_report_s) {
      const double rms =
          fixes->interval_fixes ? std::sqrt(fixes->sum2 / static_cast<double>(fixes->interval_fixes)) : NAN;
      std::printf(
          "%7.0f s  VmRSS %7ld kB  VmHWM %7ld kB  fixes %6ld  3-D error RMS %.2f m max %.2f m  |time tag - truth| max "
          "%.1f ns\n",
          t, status_kb("VmRSS:"), status_kb("VmHWM:"), fixes->fixes, rms, fixes->max_m, fixes->max_tag_s * 1e9);
      std::fflush(stdout);
      fixes->sum2 = fixes->max_m = fixes->max_tag_s = 0.0;
      fixes->interval_fixes = 0;
      next_report_s += report_every_s;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  sim::Scenario scenario;  // static, nominal constellation, 45 dB-Hz, i8 at 2.6 MHz, ionosphere on
  scenario.duration_s = argc > 1 ? std::atof(argv[1]) : 3600.0;
  const double report_every_s = argc > 2 ? std::atof(argv[2]) : 600.0;
  scenario.tow_s = 518398.0;
  pipelines::ReceiveOptions options;
  options.receiver.fs_hz = scenario.sample_rate_hz;
  options.receiver.pvt.troposphere = scenario.troposphere;
  const signals::RinexNavData nav = sim::to_rinex_nav(sim::load_navigation(scenario));
  pipelines::date_recording(options.receiver, nav, scenario.gps_week);

  FixErrors fixes;
  GeographicLib::Geocentric::WGS84().Forward(scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2],
                                             fixes.truth_e.x(), fixes.truth_e.y(), fixes.truth_e.z());
  fixes.start = {scenario.gps_week, scenario.tow_s};
  fixes.fs_hz = scenario.sample_rate_hz;
  pipelines::ReceiveSink no_sink;
  pipelines::Receiver receiver(options, {}, nav, fixes, no_sink);
  Streaming stream;
  stream.receiver = &receiver;
  stream.fixes = &fixes;
  stream.fs = scenario.sample_rate_hz;
  stream.report_every_s = stream.next_report_s = report_every_s;
  std::printf("soak: %.0f s of the nominal constellation at %.1f MHz streamed into receive (scalar, hot start)\n",
              scenario.duration_s, scenario.sample_rate_hz / 1e6);
  sim::simulate(scenario, stream);
  const pipelines::ReceiveSummary summary = receiver.finish();
  std::printf("end: %ld fixes; VmHWM %ld kB\n", fixes.fixes, status_kb("VmHWM:"));
  return fixes.fixes > 0 ? 0 : 1;
}
