// SPDX-License-Identifier: GPL-3.0-or-later
// LNAV costs: the data symbol lookup the IF synthesiser makes per sample block, and subframe decoding.
#include <benchmark/benchmark.h>

#include "signals/lnav_decoder.hpp"
#include "signals/lnav_transmitter.hpp"

using namespace ultratrack::signals;

namespace {

Ephemeris sample_ephemeris() {
  Ephemeris e;
  e.prn = 7, e.week = 2190, e.toe_s = e.toc_s = 518400.0, e.iode = e.iodc = 12;
  e.sqrt_a_sqrtm = 5153.6, e.e = 0.011, e.i0_rad = 0.96, e.omega_dot_radps = -8.1e-9, e.m0_rad = -0.6;
  return e;
}

// One call per 1 ms (a C/A code period), increasing time: the cached path.
void BM_DataSymbolAtPerMillisecond(benchmark::State& state) {
  LnavTransmitter tx(sample_ephemeris(), {}, {});
  double tow = 518400.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tx.data_symbol_at({2190, tow}));
    tow += 1e-3;
    if (tow > 600000.0) tow = 518400.0;
  }
}
BENCHMARK(BM_DataSymbolAtPerMillisecond);

void BM_DecodeSubframe(benchmark::State& state) {
  LnavTransmitter tx(sample_ephemeris(), {}, {});
  const SubframeBits bits = tx.subframe_starting_at({2190, 518400.0});
  for (auto _ : state) benchmark::DoNotOptimize(decode_lnav_subframe(bits));
}
BENCHMARK(BM_DecodeSubframe);

void BM_EncodeSubframe(benchmark::State& state) {
  LnavTransmitter tx(sample_ephemeris(), {}, {});
  double tow = 518400.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tx.subframe_starting_at({2190, tow}));
    tow += 6.0;
    if (tow > 600000.0) tow = 518400.0;
  }
}
BENCHMARK(BM_EncodeSubframe);

}  // namespace
