// 10 s of the built-in constellation simulated into memory and received as it is made, with the simulator's
// ephemerides (a hot start: the first fix once two subframe starts, 6 s apart, set the time); prints the last
// fix and its distance from the true position.
#include <GeographicLib/Geocentric.hpp>
#include <cstdio>

#include "receiver/receiver_engine.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation.hpp"

using namespace ultratrack;

struct ToReceiver final : sim::SimulationSink {  // antenna 0's blocks straight into the engine
  receiver::ReceiverEngine* engine = nullptr;
  std::int64_t next_sample = 0;
  void samples(int, std::span<const std::complex<float>> block) override {
    engine->process(block, next_sample);
    next_sample += static_cast<std::int64_t>(block.size());
  }
};

int main() {
  sim::Scenario scenario;  // defaults: static receiver, nominal constellation, 45 dB-Hz, i8 at 2.6 MHz
  scenario.duration_s = 10.0;
  scenario.tow_s = 518398.0;  // subframes start at 2 s and 8 s of signal
  receiver::ReceiverOptions options;
  options.fs_hz = scenario.sample_rate_hz;
  options.reference_week = scenario.gps_week;
  options.reference_week_is_signal_week = true;
  options.pvt.troposphere = scenario.troposphere;
  receiver::ReceiverObserver no_outputs;
  receiver::ReceiverEngine engine(options, no_outputs);
  const sim::NavigationSource nav = sim::load_navigation(scenario);
  engine.add_navigation(nav.ephemerides, nav.klobuchar, nav.utc);
  ToReceiver sink;
  sink.engine = &engine;
  sim::simulate(scenario, sink);
  if (!engine.last_fix()) return std::puts("no fix"), 1;
  Eigen::Vector3d truth;
  GeographicLib::Geocentric::WGS84().Forward(scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2],
                                             truth.x(), truth.y(), truth.z());
  const Eigen::Vector3d r = engine.last_fix()->r_e_m;
  std::printf("fix: ECEF %.1f %.1f %.1f m after %d fixes, %.2f m from the truth\n", r.x(), r.y(), r.z(),
              engine.stats().fixes, (r - truth).norm());
}
