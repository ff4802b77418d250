// 10 s of the built-in constellation simulated into memory (sim::simulate) and received as it is made by the
// library's receiver (pipelines::Receiver, scalar coupling), with the simulator's ephemerides as a hot start; prints
// the last fix and its distance from the true position.
#include <GeographicLib/Geocentric.hpp>
#include <cstdio>

#include "pipelines/receiver_pipeline.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation.hpp"

using namespace ultratrack;

struct ToReceiver final : sim::SimulationSink {  // antenna 0's blocks straight into the receiver
  pipelines::Receiver* receiver = nullptr;
  std::int64_t next_sample = 0;
  void samples(int, std::span<const std::complex<float>> block) override {
    receiver->process(block, next_sample);
    next_sample += static_cast<std::int64_t>(block.size());
  }
};

int main() {
  sim::Scenario scenario;  // defaults: static receiver, nominal constellation, 45 dB-Hz, i8 at 2.6 MHz
  scenario.duration_s = 10.0;
  scenario.tow_s = 518398.0;  // subframes start at 2 s and 8 s of signal
  pipelines::ReceiveOptions options;
  options.receiver.fs_hz = scenario.sample_rate_hz;
  options.receiver.reference_week = scenario.gps_week;
  options.receiver.reference_week_is_signal_week = true;
  options.receiver.pvt.troposphere = scenario.troposphere;  // the receiver corrects what the scenario simulates
  const sim::NavigationSource nav = sim::load_navigation(scenario);
  signals::RinexNavData hot_start;
  hot_start.ephemerides = nav.ephemerides;
  hot_start.klobuchar = nav.klobuchar;
  hot_start.utc = nav.utc;
  receiver::ReceiverObserver no_outputs;
  pipelines::ReceiveSink no_logs;
  pipelines::Receiver receiver(options, {}, hot_start, no_outputs, no_logs);
  ToReceiver sink;
  sink.receiver = &receiver;
  sim::simulate(scenario, sink);
  const pipelines::ReceiveSummary summary = receiver.finish();
  const auto& fix = receiver.engine().last_fix();
  if (!fix) return std::puts("no fix"), 1;
  Eigen::Vector3d truth;
  GeographicLib::Geocentric::WGS84().Forward(scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2],
                                             truth.x(), truth.y(), truth.z());
  std::printf("fix: ECEF %.1f %.1f %.1f m after %d fixes (first at %.1f s), %.2f m from the truth\n", fix->r_e_m.x(),
              fix->r_e_m.y(), fix->r_e_m.z(), summary.fixes, summary.ttff_s, (fix->r_e_m - truth).norm());
}
