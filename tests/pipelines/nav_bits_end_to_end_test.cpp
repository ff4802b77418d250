// SPDX-License-Identifier: GPL-3.0-or-later
// Data wipe-off end to end (issue 27): 36 s of a static receiver at 45 dB-Hz simulated in process (the shipped
// brdc3540 file, 2 MHz i8); the receiver starts hot from a nav file whose every ephemeris has Crs one unit (2^-5 m) off
// in the last place, as a generator that quantises differently makes it, so subframe 2's word 3 differs from the
// signal's. The scalar loops sum 100 ms coherently whenever 5 bits are known (adaptive_coherent off), so the bits are
// asked for at 45 dB-Hz, where every wrong wiped word shows in the prompt's signs. Default (decoded): the nav file's
// words are compared with the decoded copy and the disagreeing ones never wiped: no word contradicted. Oracle: the
// nav file re-encoded, its wrong words wiped and contradicted (counted, not acted on). summary.json's nav_bits line
// says the same.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stop_token>
#include <string>

#include "config/scenario_toml.hpp"
#include "pipelines/receiver_pipeline.hpp"
#include "receiver/receiver_summary.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"
#include "support/vector_carrier_scenarios.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

constexpr double kFs = 2.0e6;

struct Totals {
  receiver::NavBitCounts all;
  int satellites = 0;
  std::string summary;
};

Totals receive(const fs::path& samples, const signals::RinexNavData& nav, receiver::NavBitSource source,
               const fs::path& summary) {
  pipelines::ReceiveOptions o;
  o.coupling = pipelines::Coupling::kScalar;
  o.receiver.fs_hz = kFs;
  o.receiver.pvt.troposphere = false;
  o.receiver.reference_week = test::shipped_nav_week;
  o.receiver.reference_week_is_signal_week = true;
  o.receiver.tracking.adaptive_coherent = false;
  o.receiver.tracking.max_coherent_ms = 100;
  o.receiver.nav_bits = source;
  pipelines::ReceiveSink sink;
  receiver::ReceiverObserver observer;
  pipelines::Receiver rx(o, {}, nav, observer, sink);
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = kFs;
  receiver::SampleSource in(samples, signals::SampleFormat::i8, source_options);
  rx.run(in, in.total_samples(), std::stop_token{});
  rx.finish();
  Totals t;
  for (int prn = 1; prn <= 32; ++prn) {
    const receiver::NavBitCounts c = rx.engine().nav_bit_counts(prn);
    if (c.bits_wiped == 0) continue;
    t.all += c;
    ++t.satellites;
  }
  receiver::write_summary_json(summary, rx.engine(), receiver::RunDescription{});
  t.summary = test::read_text_file(summary);
  return t;
}

}  // namespace

TEST(NavBitsEndToEnd, DefaultNeverWipesWithANavFilesWrongWordsWhileTheOracleDoes) {
  const fs::path brdc = test::shipped_nav_file();
  const auto dir = test::scratch_dir();
  std::ofstream(dir / "static.toml") << test::vector_carrier_scenario(brdc, 100.0, 36.0, "");
  const auto sim = dir / "sim";
  sim::simulate_to_folder(config::read_scenario(dir / "static.toml"), sim, "");
  signals::RinexNavData nav = signals::read_rinex_nav(brdc);
  for (auto& e : nav.ephemerides) e.crs_m += std::ldexp(1.0, -5);

  const Totals decoded = receive(sim / "antenna0.i8.bin", nav, receiver::NavBitSource::kDecoded, dir / "decoded.json");
  const Totals oracle = receive(sim / "antenna0.i8.bin", nav, receiver::NavBitSource::kOracle, dir / "oracle.json");
  fs::remove(sim / "antenna0.i8.bin");

  ASSERT_GE(decoded.satellites, 6);
  EXPECT_GT(decoded.all.bits_wiped, 0);
  EXPECT_GT(decoded.all.bits_unknown, 0);         // subframe 4/5 pages, subframes 1-3 before their repetition
  EXPECT_GT(decoded.all.nav_words_disagreed, 0);  // compared, and left out
  EXPECT_GT(decoded.all.nav_words_agreed, 0);
  EXPECT_EQ(decoded.all.words_contradicted, 0);
  EXPECT_EQ(decoded.all.sources_stopped, 0);
  EXPECT_GT(decoded.all.bits_checked, 0);
  EXPECT_LE(decoded.all.bits_contradicted, decoded.all.bits_checked / 100000);  // 45 dB-Hz: no bit errors

  ASSERT_GE(oracle.satellites, 6);
  EXPECT_GE(oracle.all.words_contradicted, oracle.satellites);  // subframe 2 word 3 of each, at least
  EXPECT_EQ(oracle.all.sources_stopped, 0);                     // the oracle is never stopped
  EXPECT_GT(oracle.all.bits_wiped, decoded.all.bits_wiped);
  EXPECT_EQ(oracle.all.bits_unknown, 0);

  EXPECT_NE(decoded.summary.find("\"nav_bits\": {\"mode\": \"decoded\", \"per_satellite\": [{\"prn\": "),
            std::string::npos);
  EXPECT_NE(oracle.summary.find("\"nav_bits\": {\"mode\": \"oracle\""), std::string::npos);
  EXPECT_NE(oracle.summary.find("\"source\": \"oracle\""), std::string::npos);
  EXPECT_EQ(decoded.summary.find("\"source\": \"oracle\""), std::string::npos);
  int listed = 0;
  for (auto at = decoded.summary.find("\"words_contradicted\": "); at != std::string::npos;
       at = decoded.summary.find("\"words_contradicted\": ", at + 1), ++listed)
    EXPECT_EQ(std::stoi(decoded.summary.substr(at + 22)), 0);
  EXPECT_GE(listed, decoded.satellites);
}
