// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/receiver_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "pipelines/gnss_ins_coupler.hpp"
#include "pipelines/ultratight_loop.hpp"
#include "pipelines/vector_loop_driver.hpp"
#include "receiver/receiver_summary.hpp"
#include "receiver/sample_prefetcher.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kBlock_s = 0.05;  // run(): samples per block

const ReceiveOptions& checked(const ReceiveOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("pipelines::Receiver: " + why);
  return options;
}

}  // namespace

struct Receiver::Impl {
  ReceiveOptions options;
  std::unique_ptr<GnssInsCoupler> fusion;  // loose, tight, ultra-tight (before the engine: it observes for it)
  receiver::ReceiverEngine engine;
  std::optional<VectorLoopDriver> vector;
  std::optional<UltraTightLoop> ultratight;
  bool interrupted = false;

  Impl(const ReceiveOptions& o, std::vector<ins::ImuIncrement> imu, const signals::RinexNavData& nav,
       receiver::ReceiverObserver& observer, ReceiveSink& sink)
      : options(checked(o)),
        fusion(uses_imu(o.coupling)
                   ? std::make_unique<GnssInsCoupler>(o, std::move(imu), observer, sink, nav.ephemerides)
                   : nullptr),
        engine(o.receiver, fusion ? static_cast<receiver::ReceiverObserver&>(*fusion) : observer) {
    if (fusion) fusion->attach(engine);
    if (!nav.ephemerides.empty()) engine.add_navigation(nav.ephemerides, nav.klobuchar, nav.utc);
    if (o.coupling == Coupling::kVector)
      vector.emplace(o.receiver, sink, o.vector_carrier, o.nis_release).attach(engine);
    if (o.coupling == Coupling::kUltraTight) {
      UltraTightLoopOptions ut;
      ut.nis = o.nis_release;
      ut.common_clock_bw_hz = o.ut_clock_loop_bw_hz;
      ultratight.emplace(*fusion, sink, ut).attach(engine);
    }
  }
};

Receiver::Receiver(const ReceiveOptions& options, std::vector<ins::ImuIncrement> imu,
                   const signals::RinexNavData& navigation, receiver::ReceiverObserver& observer, ReceiveSink& sink)
    : impl_(std::make_unique<Impl>(options, std::move(imu), navigation, observer, sink)) {}

Receiver::~Receiver() = default;

void Receiver::process(std::span<const std::complex<float>> samples, std::int64_t first_sample) {
  impl_->engine.process(samples, first_sample);
}

void Receiver::process(std::span<const std::complex<float>> samples, std::int64_t first_sample, receiver::PlanarI16 i16,
                       float i16_gain) {
  impl_->engine.process(samples, first_sample, i16, i16_gain);
}

void Receiver::run(receiver::SampleSource& source, std::int64_t count, std::stop_token stop,
                   const std::function<void(const receiver::ReceiverEngine&)>& on_block) {
  receiver::ReceiverEngine& engine = impl_->engine;
  const auto block_size =
      static_cast<std::size_t>(std::max<std::int64_t>(1, std::llround(kBlock_s * impl_->options.receiver.fs_hz)));
  // With more than one thread the next block is read (and converted to int16) while this one is processed.
  receiver::SamplePrefetcher reader(source, block_size, count, engine.threads() > 1);
  while (!stop.stop_requested()) {
    const receiver::PrefetchedBlock got = reader.next();
    if (got.where.count == 0) return;
    engine.process(got.samples, got.where.first_sample, {got.re, got.im}, got.i16_gain);
    reader.set_i16_gain(engine.i16_gain());
    if (on_block) on_block(engine);
  }
  impl_->interrupted = true;
}

ReceiveSummary Receiver::finish() {
  Impl& m = *impl_;
  m.engine.finish_vector_loop();  // a pipelined loop's last update
  const receiver::ReceiverStats& stats = m.engine.stats();
  ReceiveSummary s;
  s.coupling = m.options.coupling;
  s.processed_s = receiver::processed_seconds(m.engine);
  s.interrupted = m.interrupted;
  s.threads = m.engine.threads();
  for (int prn = 1; prn <= 32; ++prn) {
    const receiver::SatelliteStats& sat = stats.satellites[static_cast<std::size_t>(prn)];
    s.satellites_found = s.satellites_found || sat.acquisitions > 0;
    s.satellites_used += sat.used_in_fixes > 0;
    s.satellites_tracked += m.engine.tracked_time_s(prn) > 0.0;
  }
  s.fixes = stats.fixes;
  s.ephemerides_decoded = m.engine.decoded_ephemerides().size();
  s.ttff_s = receiver::ttff_seconds(m.engine);
  if (stats.fixes > 0) {
    s.mean_lat_deg = stats.sum_lat_rad / stats.fixes * 180.0 / M_PI;
    s.mean_lon_deg = stats.sum_lon_rad / stats.fixes * 180.0 / M_PI;
    s.mean_height_m = stats.sum_height_m / stats.fixes;
  }
  const std::int64_t end_sample = stats.first_sample + stats.samples_processed;
  if (m.fusion) {
    m.fusion->finish(end_sample);
    s.summary_json = m.fusion->summary_json();
    s.navigation_started = m.fusion->started();
    s.navigation_not_started = m.fusion->not_started_reason();
    s.final_sigma = m.fusion->final_sigma();
  }
  if (m.ultratight) {
    m.ultratight->finish(end_sample);
    s.summary_json += ",\n  " + m.ultratight->summary_json();
    s.handed_over = m.ultratight->handed_over();
    s.ultratight_channel_epochs = m.ultratight->channel_epochs();
  }
  if (m.fusion) s.navigation_rows = m.fusion->nav_rows();  // the ultra-tight loop's last rows included
  if (m.vector) {
    s.summary_json = m.vector->summary_json();
    s.vector_epochs = m.vector->vector_epochs();
    s.vector_channel_epochs = m.vector->vector_channel_epochs();
    s.coasting_channel_epochs = m.vector->coasting_channel_epochs();
    s.vector_filter_starts = m.vector->filter().initialisations();
    s.vector_filter_resets = m.vector->filter().resets();
    s.report.push_back(m.vector->report());
  }
  if (m.fusion) s.report.push_back(m.fusion->report());
  if (m.ultratight) s.report.push_back(m.ultratight->report());
  return s;
}

const receiver::ReceiverEngine& Receiver::engine() const { return impl_->engine; }
const ReceiveOptions& Receiver::options() const { return impl_->options; }

}  // namespace ultratrack::pipelines
