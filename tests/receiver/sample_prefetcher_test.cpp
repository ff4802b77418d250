// SPDX-License-Identifier: GPL-3.0-or-later
// SamplePrefetcher on a file of known i8 values: with and without the reader thread, blocks come out in file
// order with the file's values (the limit and the file's end respected), and once a gain is set the planar
// int16 copy is round(value * gain) (exact for the gains used: integer values times a power of two).
#include "receiver/sample_prefetcher.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "support/test_data.hpp"

using namespace ultratrack::receiver;
using ultratrack::signals::SampleFormat;

namespace {

// Sample k of the file: I = (k * 7) mod 255 - 127, Q = 100 - (k * 13) mod 201 (both fit in int8).
int value_i(std::int64_t k) { return static_cast<int>((k * 7) % 255) - 127; }
int value_q(std::int64_t k) { return 100 - static_cast<int>((k * 13) % 201); }

std::filesystem::path write_i8_file(std::int64_t samples) {
  const auto path = ultratrack::test::scratch_dir() / "prefetcher_i8.bin";
  std::ofstream out(path, std::ios::binary);
  for (std::int64_t k = 0; k < samples; ++k) {
    const char iq[2] = {static_cast<char>(value_i(k)), static_cast<char>(value_q(k))};
    out.write(iq, 2);
  }
  return path;
}

struct Seen {
  std::int64_t samples = 0, converted = 0, blocks = 0;
  bool in_order = true, values_ok = true, i16_ok = true;
};

// Reads everything through a prefetcher with `limit`, setting the gain after the second block.
Seen read_all(const std::filesystem::path& path, std::int64_t skip, std::int64_t limit, std::size_t block,
              bool threaded) {
  SampleSourceOptions o;
  o.fs_hz = 2e6;
  o.start_sample = skip;
  SampleSource source(path, SampleFormat::i8, o);
  SamplePrefetcher reader(source, block, limit, threaded);
  Seen seen;
  std::int64_t expect = skip;
  for (;;) {
    const PrefetchedBlock b = reader.next();
    if (b.where.count == 0) break;
    ++seen.blocks;
    seen.in_order =
        seen.in_order && b.where.first_sample == expect && b.samples.size() == b.where.count && b.where.count <= block;
    for (std::size_t i = 0; i < b.where.count; ++i) {
      const std::int64_t k = expect + static_cast<std::int64_t>(i);
      seen.values_ok = seen.values_ok && b.samples[i] == std::complex<float>(static_cast<float>(value_i(k)),
                                                                             static_cast<float>(value_q(k)));
      if (b.i16_gain > 0.0f)
        seen.i16_ok = seen.i16_ok && b.i16_gain == 64.0f && b.re[i] == value_i(k) * 64 && b.im[i] == value_q(k) * 64;
    }
    if (b.i16_gain > 0.0f) seen.converted += static_cast<std::int64_t>(b.where.count);
    expect += static_cast<std::int64_t>(b.where.count);
    seen.samples += static_cast<std::int64_t>(b.where.count);
    if (seen.blocks == 2) {
      reader.set_i16_gain(64.0f);
      reader.set_i16_gain(32.0f);  // ignored: the first gain sticks
    }
  }
  EXPECT_EQ(reader.next().where.count, 0u);  // the end stays the end
  return seen;
}

}  // namespace

TEST(SamplePrefetcher, BlocksComeInFileOrderWithTheFilesValuesAndInt16AfterTheGain) {
  const std::int64_t total = 100003;
  const auto path = write_i8_file(total);
  for (const bool threaded : {false, true}) {
    // Whole file (the last block short), then a limit inside the file from a skipped start.
    const Seen all = read_all(path, 0, total + 10, 4096, threaded);
    EXPECT_EQ(all.samples, total) << threaded;
    EXPECT_EQ(all.blocks, (total + 4095) / 4096);
    EXPECT_TRUE(all.in_order && all.values_ok && all.i16_ok) << threaded;
    // Blocks read after the gain was set carry int16: with the thread, the one read ahead may not (at most
    // one block ahead, so at most 3 blocks without).
    EXPECT_GE(all.converted, total - 3 * 4096) << threaded;
    if (!threaded) {
      EXPECT_EQ(all.converted, total - 2 * 4096);
    }
    const Seen part = read_all(path, 777, 50000, 999, threaded);
    EXPECT_EQ(part.samples, 50000);
    EXPECT_TRUE(part.in_order && part.values_ok && part.i16_ok) << threaded;
  }
}

// A prefetcher dropped before the end (e.g. an interrupted run) stops its reader cleanly.
TEST(SamplePrefetcher, StopsWhenDroppedEarly) {
  const auto path = write_i8_file(50000);
  SampleSourceOptions o;
  o.fs_hz = 2e6;
  SampleSource source(path, SampleFormat::i8, o);
  {
    SamplePrefetcher reader(source, 1000, 50000, true);
    EXPECT_EQ(reader.next().where.count, 1000u);
  }
  EXPECT_LE(source.next_sample(), 3000);  // read at most two blocks ahead of the one taken
}
