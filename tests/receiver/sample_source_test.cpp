// SPDX-License-Identifier: GPL-3.0-or-later
// SampleSource / BasebandConverter against closed forms: a tone at IF + df comes out at df (complex) or as
// s/2 at df plus its image at -(2 IF + df) (real), phase-continuous across any block split; I/Q fix-ups
// on known values; int16 output scaling; bad options are InputErrors naming the file.
#include "receiver/sample_source.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "signals/input_error.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::receiver;
using ultratrack::signals::SampleFormat;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Mean of y[n] * exp(-j 2 pi f n / fs): the complex amplitude of a tone at f.
std::complex<double> tone_amplitude(const std::vector<std::complex<float>>& y, double f, double fs, std::int64_t n0) {
  std::complex<double> sum;
  for (std::size_t i = 0; i < y.size(); ++i)
    sum += std::complex<double>(y[i]) *
           std::polar(1.0, -kTwoPi * f * static_cast<double>(n0 + static_cast<std::int64_t>(i)) / fs);
  return sum / static_cast<double>(y.size());
}

}  // namespace

TEST(BasebandConverter, ComplexToneAtIfComesOutAtItsOffsetWhateverTheBlockSplit) {
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  o.if_hz = 1.25e6 + 0.123;
  const double df = 1234.5;
  const std::size_t n = 40000;
  std::vector<std::complex<float>> x(n);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = std::polar(
        1.0f, static_cast<float>(std::fmod(kTwoPi * (o.if_hz + df) * static_cast<double>(i) / o.fs_hz + 0.5, kTwoPi)));
  BasebandConverter converter(o, true);
  std::vector<std::complex<float>> y = x;
  const std::size_t splits[] = {1, 999, 4000, 7, 15000};  // odd block sizes, then the rest
  std::size_t at = 0;
  for (std::size_t s : splits) {
    converter.convert(std::span(y).subspan(at, s));
    at += s;
  }
  converter.convert(std::span(y).subspan(at));
  EXPECT_EQ(converter.next_sample(), static_cast<std::int64_t>(n));
  for (std::size_t i = 0; i < n; i += 997) {
    const std::complex<float> expected =
        std::polar(1.0f, static_cast<float>(std::fmod(kTwoPi * df * static_cast<double>(i) / o.fs_hz + 0.5, kTwoPi)));
    ASSERT_NEAR(std::abs(y[i] - expected), 0.0, 2e-4) << "sample " << i;
  }
}

TEST(BasebandConverter, StartSampleKeepsTheAbsolutePhase) {
  SampleSourceOptions o;
  o.fs_hz = 12e6;
  o.if_hz = 3e6;
  o.start_sample = 123457;
  BasebandConverter converter(o, true);
  std::vector<std::complex<float>> y(1, {1.0f, 0.0f});
  converter.convert(y);
  const double phase = -kTwoPi * std::fmod(3e6 * 123457.0 / 12e6, 1.0);  // exp(-j 2 pi IF n / fs)
  EXPECT_NEAR(std::abs(y[0] - std::complex<float>(std::polar(1.0, phase))), 0.0, 1e-6);
  EXPECT_EQ(converter.next_sample(), 123458);
}

TEST(BasebandConverter, RealInputGivesHalfAmplitudeToneAndImageAtMinusTwoIf) {
  SampleSourceOptions o;
  o.fs_hz = 12e6;
  o.if_hz = 3e6;
  const double df = -2500.0;
  const std::size_t n = 120000;  // 10 ms: tones 1 kHz apart or more are orthogonal to 1e-4
  std::vector<std::complex<float>> y(n);
  for (std::size_t i = 0; i < n; ++i)
    y[i] = {static_cast<float>(std::cos(kTwoPi * (o.if_hz + df) * static_cast<double>(i) / o.fs_hz)), 0.0f};
  auto y_inverted = y;
  BasebandConverter(o, false).convert(y);
  EXPECT_NEAR(std::abs(tone_amplitude(y, df, o.fs_hz, 0) - 0.5), 0.0, 1e-3);
  EXPECT_NEAR(std::abs(tone_amplitude(y, -(2.0 * o.if_hz + df), o.fs_hz, 0)), 0.5, 1e-3);
  EXPECT_NEAR(std::abs(tone_amplitude(y, -df, o.fs_hz, 0)), 0.0, 1e-3);
  // --q-negate on real input: spectrum inverted, the tone comes out at -df.
  o.q_negate = true;
  BasebandConverter(o, false).convert(y_inverted);
  EXPECT_NEAR(std::abs(tone_amplitude(y_inverted, -df, o.fs_hz, 0) - 0.5), 0.0, 1e-3);
}

TEST(BasebandConverter, IqSwapAndQNegateOnKnownValues) {
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  std::vector<std::complex<float>> y{{1.0f, 2.0f}, {-3.0f, 4.0f}};
  o.iq_swap = true;
  BasebandConverter(o, true).convert(y);
  EXPECT_EQ(y[0], std::complex<float>(2.0f, 1.0f));
  EXPECT_EQ(y[1], std::complex<float>(4.0f, -3.0f));
  o.iq_swap = false;
  o.q_negate = true;
  BasebandConverter(o, true).convert(y);
  EXPECT_EQ(y[0], std::complex<float>(2.0f, -1.0f));
  EXPECT_EQ(y[1], std::complex<float>(4.0f, 3.0f));
}

TEST(SampleSourceOptions, RejectsOptionsNoRecordingCanHave) {
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  EXPECT_TRUE(o.IsValid(SampleFormat::i8, nullptr));
  EXPECT_FALSE(o.IsValid(SampleFormat::r8, nullptr));  // real samples need an IF
  o.if_hz = 2e6;
  EXPECT_FALSE(o.IsValid(SampleFormat::r8, nullptr));  // at fs/2
  o.if_hz = 1e6;
  o.iq_swap = true;
  EXPECT_FALSE(o.IsValid(SampleFormat::r16, nullptr));
  EXPECT_TRUE(o.IsValid(SampleFormat::i16, nullptr));
  o.fs_hz = 0.0;
  EXPECT_FALSE(o.IsValid(SampleFormat::i16, nullptr));
}

TEST(SampleSource, ReadsBlocksWithCountersAndInt16Output) {
  const auto path = ultratrack::test::scratch_dir() / "tone.i8";
  {
    std::ofstream f(path, std::ios::binary);
    for (int i = 0; i < 1000; ++i) {
      const signed char iq[2] = {static_cast<signed char>(i % 7 - 3), static_cast<signed char>(-(i % 5))};
      f.write(reinterpret_cast<const char*>(iq), 2);
    }
  }
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  o.q_negate = true;
  o.start_sample = 10;
  SampleSource source(path, SampleFormat::i8, o);
  EXPECT_EQ(source.total_samples(), 1000);
  std::vector<std::complex<float>> block(600);
  const SampleBlock a = source.read(block);
  EXPECT_EQ(a.first_sample, 10);
  EXPECT_EQ(a.count, 600u);
  EXPECT_EQ(block[0], std::complex<float>(10 % 7 - 3, 10 % 5));  // Q negated
  std::vector<std::complex<std::int16_t>> ints(600);
  const SampleBlock b = source.read(ints);
  EXPECT_EQ(b.first_sample, 610);
  EXPECT_EQ(b.count, 390u);  // the end of the file
  EXPECT_EQ(ints[0], (std::complex<std::int16_t>(static_cast<std::int16_t>((610 % 7 - 3) * 64),
                                                 static_cast<std::int16_t>((610 % 5) * 64))));
  EXPECT_EQ(source.read(block).count, 0u);
}

TEST(SampleSource, BadOptionsAndFilesAreInputErrors) {
  const auto dir = ultratrack::test::scratch_dir();
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  EXPECT_THROW(SampleSource(dir / "missing.bin", SampleFormat::i8, o), ultratrack::signals::InputError);
  { std::ofstream(dir / "x.r8", std::ios::binary) << "abcd"; }
  try {
    SampleSource(dir / "x.r8", SampleFormat::r8, o);  // real format without an IF
    FAIL() << "no InputError";
  } catch (const ultratrack::signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.r8"), std::string::npos);
  }
}

TEST(SampleSource, FloatFilesGetAnInt16ScaleFromTheirOwnLevel) {
  // gr_complex files have no full scale (the CTTC capture has an RMS of 177): the int16 output must
  // neither saturate nor vanish. Gaussian noise of RMS 177 must come out with RMS 2048.
  const auto path = ultratrack::test::scratch_dir() / "noise.f32";
  {
    std::ofstream f(path, std::ios::binary);
    std::mt19937 rng(4);
    std::normal_distribution<float> normal(0.0f, 177.0f / std::sqrt(2.0f));
    for (int i = 0; i < 100000; ++i) {
      const float iq[2] = {normal(rng), normal(rng)};
      f.write(reinterpret_cast<const char*>(iq), sizeof iq);
    }
  }
  SampleSourceOptions o;
  o.fs_hz = 4e6;
  SampleSource source(path, SampleFormat::f32, o);
  std::vector<std::complex<std::int16_t>> out(100000);
  ASSERT_EQ(source.read(out).count, out.size());
  double power = 0.0;
  int saturated = 0;
  for (const auto& v : out) {
    power += double(v.real()) * v.real() + double(v.imag()) * v.imag();
    saturated += (std::abs(v.real()) == 32767 || std::abs(v.imag()) == 32767) ? 1 : 0;
  }
  EXPECT_NEAR(std::sqrt(power / out.size()), 2048.0, 2048.0 * 0.01);  // 1e5 samples: 0.2 % (1 sigma)
  EXPECT_EQ(saturated, 0);
  o.int16_gain = 3.0;
  EXPECT_FLOAT_EQ(SampleSource(path, SampleFormat::f32, o).int16_gain(), 3.0f);
}
