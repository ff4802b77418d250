// SPDX-License-Identifier: GPL-3.0-or-later
// Correlator engine throughput: carrier wipe-off plus 1, 3 or 5 code correlators over 1 ms blocks at 4 MHz,
// for 1 and 3 antennas against one replica. Reports samples/s per antenna stream (items) and per call. Also the
// receiver's own layout (early, prompt, late and the noise tap) over a 1 ms block at 2.6 MHz.
// ULTRATRACK_CORRELATOR_ISA=baseline|avx2|avx512 picks the copy measured (default: the best the CPU has).
#include <benchmark/benchmark.h>

#include <complex>
#include <random>
#include <vector>

#include "receiver/correlator_engine.hpp"

using namespace ultratrack::receiver;

namespace {
void BM_Correlate(benchmark::State& state) {
  const int taps = static_cast<int>(state.range(0));
  const int antennas = static_cast<int>(state.range(1));
  const int n = 4000;  // 1 ms at 4 MHz
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<std::vector<std::complex<float>>> data(antennas, std::vector<std::complex<float>>(n));
  for (auto& a : data)
    for (auto& x : a) x = {g(rng), g(rng)};
  const double all_offsets[] = {0.0, 0.5, -0.5, 1.0, -1.0};
  CorrelatorEngine engine(7, std::span<const double>(all_offsets, taps));
  std::vector<const std::complex<float>*> ptr;
  for (auto& a : data) ptr.push_back(a.data());
  ReplicaSegment rep;
  rep.code_phase_chips = 0.3;
  rep.code_step_chips = 1.023e6 / 4e6;
  rep.carrier_step_q32 = static_cast<std::uint32_t>(1234.5 / 4e6 * 4294967296.0);
  std::vector<TapSums> sums(antennas);
  for (auto _ : state) {
    engine.correlate(ptr, n, rep, sums);
    benchmark::DoNotOptimize(sums.data());
    rep.carrier_phase_q32 += 12345u;
  }
  state.SetItemsProcessed(state.iterations() * n * antennas);  // samples consumed (all antennas)
  state.counters["Msamples_per_s_per_antenna"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n / 1e6, benchmark::Counter::kIsRate);
}
void BM_CorrelateReceiverLayout(benchmark::State& state) {
  const int n = 2600;  // 1 ms at 2.6 MHz
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<std::complex<float>> data(n);
  for (auto& x : data) x = {g(rng), g(rng)};
  const double offsets[] = {0.5, 0.0, -0.5, noise_tap_offset_chips(7)};
  CorrelatorEngine engine(7, offsets);
  const std::complex<float>* ptr[] = {data.data()};
  ReplicaSegment rep;
  rep.code_phase_chips = 0.3;
  rep.code_step_chips = 1.023e6 / 2.6e6;
  rep.carrier_step_q32 = static_cast<std::uint32_t>(1234.5 / 2.6e6 * 4294967296.0);
  TapSums sums[1]{};
  for (auto _ : state) {
    engine.correlate(ptr, n, rep, sums);
    benchmark::DoNotOptimize(sums);
    rep.carrier_phase_q32 += 12345u;
  }
  state.SetItemsProcessed(state.iterations() * n);
}
// The integer kernel on the same layouts: samples as planar int16 (the receiver converts each block once, shared
// by all channels; that conversion is timed separately below).
void BM_CorrelateInt16(benchmark::State& state) {
  const int taps = static_cast<int>(state.range(0));
  const int antennas = static_cast<int>(state.range(1));
  const int n = 4000;
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<std::vector<std::int16_t>> re(antennas, std::vector<std::int16_t>(n)), im = re;
  for (int a = 0; a < antennas; ++a) {
    std::vector<std::complex<float>> x(n);
    for (auto& v : x) v = {g(rng), g(rng)};
    convert_to_planar_i16(x.data(), n, 2048.0f, re[a].data(), im[a].data());
  }
  const double all_offsets[] = {0.0, 0.5, -0.5, 1.0, -1.0};
  CorrelatorEngine engine(7, std::span<const double>(all_offsets, taps));
  std::vector<PlanarI16> ptr;
  for (int a = 0; a < antennas; ++a) ptr.push_back({re[a].data(), im[a].data()});
  ReplicaSegment rep;
  rep.code_phase_chips = 0.3;
  rep.code_step_chips = 1.023e6 / 4e6;
  rep.carrier_step_q32 = static_cast<std::uint32_t>(1234.5 / 4e6 * 4294967296.0);
  std::vector<TapSums> sums(antennas);
  for (auto _ : state) {
    engine.correlate_i16(ptr, n, rep, 1.0 / 2048.0, sums);
    benchmark::DoNotOptimize(sums.data());
    rep.carrier_phase_q32 += 12345u;
  }
  state.SetItemsProcessed(state.iterations() * n * antennas);
  state.counters["Msamples_per_s_per_antenna"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n / 1e6, benchmark::Counter::kIsRate);
}
// Receiver layout, integer kernel. Half-epoch calls (1300 samples) as the tracking channel makes them, with the
// carrier step changing every epoch (every other call), so the rotation table is rebuilt as in the receiver.
void BM_CorrelateInt16ReceiverLayout(benchmark::State& state) {
  const int n = 2600;
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<std::complex<float>> data(n);
  for (auto& x : data) x = {g(rng), g(rng)};
  std::vector<std::int16_t> re(n), im(n);
  convert_to_planar_i16(data.data(), n, 2048.0f, re.data(), im.data());
  const double offsets[] = {0.5, 0.0, -0.5, noise_tap_offset_chips(7)};
  CorrelatorEngine engine(7, offsets);
  ReplicaSegment rep;
  rep.code_phase_chips = 0.3;
  rep.code_step_chips = 1.023e6 / 2.6e6;
  rep.carrier_step_q32 = static_cast<std::uint32_t>(1234.5 / 2.6e6 * 4294967296.0);
  TapSums sums[1]{};
  for (auto _ : state) {
    for (int half = 0; half < 2; ++half) {
      const PlanarI16 ptr[] = {{re.data() + half * n / 2, im.data() + half * n / 2}};
      engine.correlate_i16(ptr, n / 2, rep, 1.0 / 2048.0, sums);
    }
    benchmark::DoNotOptimize(sums);
    rep.carrier_phase_q32 += 12345u;
    rep.carrier_step_q32 += 7u;
  }
  state.SetItemsProcessed(state.iterations() * n);
}
// The receiver's once-per-block conversion of complex float samples to planar int16.
void BM_ConvertToPlanarInt16(benchmark::State& state) {
  const int n = 130000;  // 50 ms at 2.6 MHz
  std::vector<std::complex<float>> data(n, {3.0f, -5.0f});
  std::vector<std::int16_t> re(n), im(n);
  for (auto _ : state) {
    convert_to_planar_i16(data.data(), n, 64.0f, re.data(), im.data());
    benchmark::DoNotOptimize(re.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
}
}  // namespace

BENCHMARK(BM_CorrelateInt16)->ArgNames({"taps", "antennas"})->ArgsProduct({{1, 3, 5}, {1, 3}});
BENCHMARK(BM_CorrelateInt16ReceiverLayout);
BENCHMARK(BM_ConvertToPlanarInt16);
BENCHMARK(BM_Correlate)->ArgNames({"taps", "antennas"})->ArgsProduct({{1, 3, 5}, {1, 3}});
BENCHMARK(BM_CorrelateReceiverLayout);
