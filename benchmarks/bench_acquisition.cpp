// SPDX-License-Identifier: GPL-3.0-or-later
// Acquisition time per PRN at 4 MHz: 1 ms and 10 ms coherent (one block, +-5 kHz, default step), for a
// single-PRN search and per PRN of a 32-PRN search (signal spectra shared between PRNs); and the receiver's
// default search (4 ms x 5 non-coherent) per PRN of an 8-PRN blind re-acquisition at 2.6 and 16 MHz.
// ULTRATRACK_FFTW_WISDOM=FILE in the environment measures FFTW_PATIENT plans once and reuses them.
#include <benchmark/benchmark.h>

#include <complex>
#include <numeric>
#include <random>
#include <vector>

#include "receiver/acquisition.hpp"

using namespace ultratrack::receiver;

namespace {

std::vector<std::complex<float>> noise(std::size_t n) {
  std::mt19937 rng(1);
  std::normal_distribution<float> normal;
  std::vector<std::complex<float>> x(n);
  for (auto& v : x) v = {normal(rng), normal(rng)};
  return x;
}

void BM_AcquireOnePrn(benchmark::State& state) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.coherent_ms = static_cast<int>(state.range(0));
  Acquisition acq(o);
  const auto x = noise(acq.samples_needed());
  acq.search(x, 1);  // code spectrum cached, as in a receiver
  for (auto _ : state) benchmark::DoNotOptimize(acq.search(x, 1));
  state.counters["cells"] = acq.cells();
}

void BM_AcquireAllPrnsPerPrn(benchmark::State& state) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.coherent_ms = static_cast<int>(state.range(0));
  Acquisition acq(o);
  const auto x = noise(acq.samples_needed());
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  acq.search(x, prns);
  for (auto _ : state) benchmark::DoNotOptimize(acq.search(x, prns));
  state.SetItemsProcessed(state.iterations() * 32);  // items/s = PRNs per second
}

void BM_ReceiverBlindSearchPerPrn(benchmark::State& state) {
  AcquisitionOptions o;
  o.fs_hz = static_cast<double>(state.range(0)) * 1e5;
  o.coherent_ms = 4;
  o.noncoherent = 5;
  Acquisition acq(o);
  const auto x = noise(acq.samples_needed());
  std::vector<int> prns(8);
  std::iota(prns.begin(), prns.end(), 1);
  acq.search(x, prns);
  for (auto _ : state) benchmark::DoNotOptimize(acq.search(x, prns));
  state.SetItemsProcessed(state.iterations() * 8);
}

}  // namespace

BENCHMARK(BM_AcquireOnePrn)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AcquireAllPrnsPerPrn)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReceiverBlindSearchPerPrn)->ArgName("fs_100kHz")->Arg(26)->Arg(160)->Unit(benchmark::kMillisecond);
