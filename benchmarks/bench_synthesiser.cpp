// SPDX-License-Identifier: GPL-3.0-or-later
// IF synthesiser speed: 8 (and 0, 12) satellites at 4 MHz complex, quantised to i8 and written to a file, on one core.
// The counter realtime_factor is seconds of signal per second of wall time (> 1: faster than real time).
#include <benchmark/benchmark.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <complex>
#include <filesystem>
#include <vector>

#include "signals/if_synthesiser.hpp"
#include "signals/sample_writer.hpp"
#include "signals/synth_kernels.hpp"

namespace {

using namespace ultratrack::signals;

std::vector<Ephemeris> satellites(const GpsTime& t, int count) {
  std::vector<Ephemeris> out;
  for (int k = 0; k < count; ++k) {
    Ephemeris e;
    e.prn = k + 1;
    e.week = t.week;
    e.toe_s = e.toc_s = t.tow_s;
    e.sqrt_a_sqrtm = 5153.7;
    e.e = 0.005;
    e.i0_rad = 0.96;
    e.omega0_rad = (k % 4) * 1.047;
    e.m0_rad = k * 0.785;
    e.af0_s = 1e-5 * k;
    out.push_back(e);
  }
  return out;
}

// state.range(0): number of satellites (0 shows the cost of noise, quantisation and writing alone).
void BM_Synthesise4MHzI8(benchmark::State& state) {
  SynthesiserOptions o;
  o.sample_rate_hz = 4e6;
  o.start = {2190, 518400.0};
  o.elevation_mask_rad = -M_PI / 2;  // all eight transmitted, wherever they are
  o.troposphere = true;
  Eigen::Vector3d r;
  GeographicLib::Geocentric::WGS84().Forward(35.27, 137.01, 100.0, r.x(), r.y(), r.z());
  IfSynthesiser synth(o, satellites(o.start, static_cast<int>(state.range(0))),
                      std::make_shared<StaticMotion>(std::vector<Eigen::Vector3d>{r}));
  const auto path = std::filesystem::temp_directory_path() / "ultratrack_bench_synth.i8";
  SampleWriter writer(path, SampleFormat::i8);
  std::vector<std::complex<float>> buf(400000);  // 100 ms
  std::span<std::complex<float>> span(buf);
  for (auto _ : state) {
    synth.generate(std::span<const std::span<std::complex<float>>>(&span, 1));
    writer.write(buf);
    benchmark::ClobberMemory();
  }
  const double signal_s = static_cast<double>(state.iterations()) * 0.1;
  state.counters["realtime_factor"] = benchmark::Counter(signal_s, benchmark::Counter::kIsRate);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(buf.size()));
}
BENCHMARK(BM_Synthesise4MHzI8)->Arg(8)->Arg(0)->Arg(12)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

namespace {

// The parts alone: complex Gaussian noise, and i8 quantisation + file writing, 100 ms at 4 MHz.
void BM_NoiseOnly4MHz(benchmark::State& state) {
  ultratrack::signals::synth::GaussianNoise noise(1, 1);
  std::vector<std::complex<float>> buf(400000);
  for (auto _ : state) {
    noise.fill(buf.data(), buf.size(), 30.0f, false);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(buf.size()));
}
BENCHMARK(BM_NoiseOnly4MHz)->Unit(benchmark::kMillisecond);

void BM_WriteI8Only4MHz(benchmark::State& state) {
  ultratrack::signals::synth::GaussianNoise noise(1, 1);
  std::vector<std::complex<float>> buf(400000);
  noise.fill(buf.data(), buf.size(), 30.0f, false);
  ultratrack::signals::SampleWriter writer(std::filesystem::temp_directory_path() / "ultratrack_bench_w.i8",
                                           ultratrack::signals::SampleFormat::i8);
  for (auto _ : state) writer.write(buf);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(buf.size()));
}
BENCHMARK(BM_WriteI8Only4MHz)->Unit(benchmark::kMillisecond);

}  // namespace
