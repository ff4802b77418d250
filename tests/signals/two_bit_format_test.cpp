// SPDX-License-Identifier: GPL-3.0-or-later
// Packed 2-bit formats (r2, i2): decoding of hand-written bytes against the conventions as the peers write
// them (GNSS-SDR's unpack_2bit_samples: a signed 2-bit field v gives 2v + 1; PocketSDR's MAX2771 table
// {+1, +3, -1, -3} indexed by the field; GNSS-SDR's NTLab unpacker: high bit magnitude, low bit sign = +),
// write -> read round trips, start samples inside a byte, the quantiser's thresholds and its 2-bit loss
// against the closed form, and the errors for empty, short and shrinking files.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "signals/input_error.hpp"
#include "signals/sample_format.hpp"
#include "signals/sample_reader.hpp"
#include "signals/sample_writer.hpp"
#include "support/test_data.hpp"

namespace ultratrack::signals {
namespace {

void write_raw(const std::filesystem::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream f(path, std::ios::binary);
  for (auto b : bytes) f.put(static_cast<char>(b));
}

std::vector<std::complex<float>> read_all(const std::filesystem::path& path, SampleFormat format, TwoBitLayout layout,
                                          std::int64_t start = 0, std::size_t block = 7) {
  SampleReader reader(path, format, start, layout);
  std::vector<std::complex<float>> all, buf(block);
  while (std::size_t n = reader.read(buf)) all.insert(all.end(), buf.begin(), buf.begin() + n);
  return all;
}

std::vector<float> reals(const std::vector<std::complex<float>>& x) {
  std::vector<float> r;
  for (const auto& v : x) r.push_back(v.real());
  return r;
}

TEST(TwoBitFormat, NamesAndSizes) {
  EXPECT_EQ(parse_sample_format("r2"), SampleFormat::r2);
  EXPECT_EQ(parse_sample_format("i2"), SampleFormat::i2);
  EXPECT_EQ(to_string(SampleFormat::i2), "i2");
  EXPECT_TRUE(is_complex(SampleFormat::i2));
  EXPECT_FALSE(is_complex(SampleFormat::r2));
  EXPECT_EQ(samples_per_byte(SampleFormat::r2), 4u);
  EXPECT_EQ(samples_per_byte(SampleFormat::i2), 2u);
  EXPECT_EQ(samples_per_byte(SampleFormat::i8), 0u);
  EXPECT_EQ(bytes_per_sample(SampleFormat::r2), 0u);
  EXPECT_EQ(full_scale(SampleFormat::i2), 3.0);
  EXPECT_EQ(nominal_rms(SampleFormat::r2), 2.0);
  for (auto c :
       {TwoBitCoding::twos_complement, TwoBitCoding::sign_magnitude, TwoBitCoding::offset_binary, TwoBitCoding::nt1065})
    EXPECT_EQ(parse_two_bit_coding(to_string(c)), c);
  EXPECT_EQ(parse_bit_order("msb-first"), BitOrder::msb_first);
  EXPECT_FALSE(parse_two_bit_coding("ones").has_value());
  EXPECT_FALSE(parse_bit_order("little").has_value());
}

// One byte 0xE4 = fields 11 10 01 00 (bits 7:6 .. 1:0), worked by hand for each convention.
TEST(TwoBitFormat, DecodesHandWrittenBytes) {
  const auto dir = test::scratch_dir();
  const auto path = dir / "e4.bin";
  write_raw(path, {0xE4});
  struct Case {
    TwoBitCoding coding;
    BitOrder order;
    std::vector<float> levels;
  };
  const Case cases[] = {
      {TwoBitCoding::twos_complement, BitOrder::lsb_first, {+1, +3, -3, -1}},  // 00 01 10 11 as 2v+1
      {TwoBitCoding::twos_complement, BitOrder::msb_first, {-1, -3, +3, +1}},
      {TwoBitCoding::sign_magnitude, BitOrder::lsb_first, {+1, +3, -1, -3}},
      {TwoBitCoding::offset_binary, BitOrder::lsb_first, {-3, -1, +1, +3}},
      {TwoBitCoding::nt1065, BitOrder::msb_first, {+3, -3, +1, -1}},  // 11: M1 S1, 10: M1 S0, 01, 00
  };
  for (const auto& c : cases) {
    const TwoBitLayout layout{c.coding, c.order};
    EXPECT_EQ(reals(read_all(path, SampleFormat::r2, layout)), c.levels)
        << to_string(c.coding) << " " << to_string(c.order);
    const auto iq = read_all(path, SampleFormat::i2, layout);
    ASSERT_EQ(iq.size(), 2u);
    EXPECT_EQ(iq[0], std::complex<float>(c.levels[0], c.levels[1]));
    EXPECT_EQ(iq[1], std::complex<float>(c.levels[2], c.levels[3]));
  }
}

// Every byte value against the peers' closed forms (not our table).
TEST(TwoBitFormat, DecodesEveryByteAsThePeersDo) {
  const auto dir = test::scratch_dir();
  const auto path = dir / "all.bin";
  std::vector<unsigned char> bytes;
  for (int b = 0; b < 256; ++b) bytes.push_back(static_cast<unsigned char>(b));
  write_raw(path, bytes);
  auto field = [](int b, int j) { return (b >> (2 * j)) & 3; };
  auto twos = [](int f) { return 2 * (f >= 2 ? f - 4 : f) + 1; };               // GNSS-SDR: 2 * signed(f) + 1
  auto signmag = [](int f) { return ((f & 2) ? -1 : 1) * ((f & 1) ? 3 : 1); };  // PocketSDR {+1, +3, -1, -3}
  auto nt = [](int f) { return ((f & 1) ? 1 : -1) * ((f & 2) ? 3 : 1); };       // NTLab: M = bit 1, S = bit 0
  const auto tw = reals(read_all(path, SampleFormat::r2, {TwoBitCoding::twos_complement, BitOrder::lsb_first}));
  const auto twm = reals(read_all(path, SampleFormat::r2, {TwoBitCoding::twos_complement, BitOrder::msb_first}));
  const auto sm = reals(read_all(path, SampleFormat::r2, {TwoBitCoding::sign_magnitude, BitOrder::lsb_first}));
  const auto ob = reals(read_all(path, SampleFormat::r2, {TwoBitCoding::offset_binary, BitOrder::lsb_first}));
  const auto ntm = reals(read_all(path, SampleFormat::r2, {TwoBitCoding::nt1065, BitOrder::msb_first}));
  ASSERT_EQ(tw.size(), 1024u);
  for (int b = 0; b < 256; ++b) {
    for (int j = 0; j < 4; ++j) {
      const auto i = 4 * static_cast<std::size_t>(b) + static_cast<std::size_t>(j);
      EXPECT_EQ(tw[i], twos(field(b, j))) << b << " " << j;
      EXPECT_EQ(twm[i], twos(field(b, 3 - j))) << b << " " << j;
      EXPECT_EQ(sm[i], signmag(field(b, j))) << b << " " << j;
      EXPECT_EQ(ob[i], 2 * field(b, j) - 3) << b << " " << j;
      EXPECT_EQ(ntm[i], nt(field(b, 3 - j))) << b << " " << j;
    }
  }
}

std::vector<std::complex<float>> random_levels(std::size_t n, bool complex, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, 3);
  auto level = [&] { return static_cast<float>(2 * pick(rng) - 3); };
  std::vector<std::complex<float>> x;
  for (std::size_t i = 0; i < n; ++i) {
    const float re = level();
    x.emplace_back(re, complex ? level() : 0.0f);
  }
  return x;
}

TEST(TwoBitFormat, RoundTripsFromEveryStartSampleAndBlockSize) {
  const auto dir = test::scratch_dir();
  for (auto format : {SampleFormat::r2, SampleFormat::i2}) {
    for (auto order : {BitOrder::lsb_first, BitOrder::msb_first}) {
      for (auto coding : {TwoBitCoding::twos_complement, TwoBitCoding::sign_magnitude, TwoBitCoding::offset_binary,
                          TwoBitCoding::nt1065}) {
        const TwoBitLayout layout{coding, order};
        const std::size_t n = 37;  // not a whole number of bytes for either format
        const auto in = random_levels(n, is_complex(format), 3);
        const auto path = dir / ("rt." + std::string(to_string(format)));
        {
          SampleWriter w(path, format, layout);
          w.write(std::span(in).first(5));  // cuts a byte between two writes
          w.write(std::span(in).subspan(5));
          w.finish();
        }
        const std::size_t per_byte = samples_per_byte(format);
        const std::size_t padded = (n + per_byte - 1) / per_byte * per_byte;
        ASSERT_EQ(std::filesystem::file_size(path), padded / per_byte);
        for (std::int64_t start = 0; start < static_cast<std::int64_t>(n); ++start) {
          for (std::size_t block : {1u, 3u, 8u, 64u}) {
            const auto out = read_all(path, format, layout, start, block);
            ASSERT_EQ(out.size(), padded - static_cast<std::size_t>(start));
            for (std::size_t i = 0; i + static_cast<std::size_t>(start) < n; ++i)
              ASSERT_EQ(out[i], in[i + static_cast<std::size_t>(start)])
                  << to_string(format) << " " << to_string(coding) << " " << to_string(order) << " start " << start
                  << " block " << block << " sample " << i;
            // The padding of the last byte is +1 (real) / +1+1j (complex).
            for (std::size_t i = n - static_cast<std::size_t>(start); i < out.size(); ++i)
              EXPECT_EQ(out[i], std::complex<float>(1.0f, is_complex(format) ? 1.0f : 0.0f));
          }
        }
      }
    }
  }
}

TEST(TwoBitFormat, QuantiserThresholdsAreMinus2Zero2) {
  const auto dir = test::scratch_dir();
  const std::vector<float> x = {-10.0f, -2.5f, -2.01f, -1.99f, -0.1f, 0.0f, 0.1f, 1.99f, 2.0f, 2.5f, 10.0f, NAN};
  const std::vector<float> want = {-3, -3, -3, -1, -1, +1, +1, +1, +3, +3, +3, +1};
  std::vector<std::complex<float>> in;
  for (float v : x) in.emplace_back(v, -v);
  {
    SampleWriter w(dir / "q.i2", SampleFormat::i2);
    w.write(in);
    w.finish();
  }
  const auto out = read_all(dir / "q.i2", SampleFormat::i2, {});
  ASSERT_EQ(out.size(), x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(out[i].real(), want[i]) << x[i];
    if (!std::isnan(x[i]) && x[i] != 0.0f && std::abs(x[i]) != 2.0f) {
      EXPECT_EQ(out[i].imag(), -want[i]) << -x[i];
    }
  }
}

// Gaussian noise at sigma 2 (the threshold at 1 sigma, as `simulate` writes it): the correlation of the
// quantised samples with the input, rho^2 = E[x q]^2 / (E[x^2] E[q^2]), is the SNR kept by a weak signal
// (Van Vleck); the closed form for levels 1, 3 and threshold 1 sigma is 0.88115 (-0.550 dB). 2e6 samples
// give a standard error of ~3e-4 on rho^2; tolerance 0.002.
TEST(TwoBitFormat, QuantiserLossMatchesTheClosedForm) {
  const auto dir = test::scratch_dir();
  std::mt19937 rng(9);
  std::normal_distribution<float> g(0.0f, 2.0f);
  std::vector<std::complex<float>> in(1000000);
  for (auto& v : in) v = {g(rng), g(rng)};
  {
    SampleWriter w(dir / "n.i2", SampleFormat::i2);
    w.write(in);
    w.finish();
  }
  const auto out = read_all(dir / "n.i2", SampleFormat::i2, {}, 0, 65536);
  ASSERT_EQ(out.size(), in.size());
  double xq = 0, xx = 0, qq = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    xq += in[i].real() * out[i].real() + in[i].imag() * out[i].imag();
    xx += std::norm(in[i]);
    qq += std::norm(out[i]);
  }
  const double efficiency = xq * xq / (xx * qq);
  std::printf("2-bit quantiser at 1 sigma: SNR kept %.4f (%.3f dB), closed form 0.8812 (-0.550 dB)\n", efficiency,
              10 * std::log10(efficiency));
  EXPECT_NEAR(efficiency, 0.88115, 0.002);
}

void expect_input_error(const std::function<void()>& f, const std::string& file, const std::string& words) {
  try {
    f();
    FAIL() << "no InputError for " << file;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
  }
}

TEST(TwoBitFormat, BadFilesAreInputErrorsNamingTheFile) {
  const auto dir = test::scratch_dir();
  write_raw(dir / "empty.r2", {});
  expect_input_error([&] { SampleReader r(dir / "empty.r2", SampleFormat::r2); }, "empty.r2", "empty");
  write_raw(dir / "three.i2", {0x00, 0x11, 0x22});  // 6 complex samples
  expect_input_error([&] { SampleReader r(dir / "three.i2", SampleFormat::i2, 6); }, "three.i2", "beyond the end");
  expect_input_error([&] { SampleReader r(dir / "three.i2", SampleFormat::i2, -1); }, "three.i2", "negative");
  SampleReader last(dir / "three.i2", SampleFormat::i2, 5);  // the second half of the last byte
  std::vector<std::complex<float>> buf(4);
  EXPECT_EQ(last.read(buf), 1u);
  EXPECT_EQ(buf[0], std::complex<float>(-3.0f, +1.0f));  // 0x22: fields 3..0 = 00 10 00 10; sample 1 = (f2, f3)
  // A file that shrinks while it is read (a recording cut by a full disk, a copy still running):
  write_raw(dir / "shrinks.r2", std::vector<unsigned char>(100000, 0x1B));  // beyond any stream buffer
  SampleReader r(dir / "shrinks.r2", SampleFormat::r2, 2);
  std::filesystem::resize_file(dir / "shrinks.r2", 100);
  std::vector<std::complex<float>> many(400000);
  expect_input_error([&] { r.read(many); }, "shrinks.r2", "read failed");
}

}  // namespace
}  // namespace ultratrack::signals

namespace ultratrack::signals {
namespace {

// PocketSDR's 4 MHz recording holds MAX2771 2-bit samples expanded to int8 (+-1, +-3) by PocketSDR's
// sign-magnitude table. Packed back by hand with that table (I0 bits 1:0, Q0 3:2, I1 5:4, Q1 7:6), our i2
// reader with sign-magnitude / lsb-first must give every sample of the int8 file back.
TEST(TwoBitFormat, RepackedPocketSdrRecordingReadsBackExactly) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  std::ifstream in(path, std::ios::binary);
  std::vector<char> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(raw.size() % 4, 0u);
  auto code = [](signed char v) -> unsigned char {
    switch (v) {
      case 1:
        return 0b00;
      case 3:
        return 0b01;
      case -1:
        return 0b10;
      case -3:
        return 0b11;
    }
    ADD_FAILURE() << "value " << int(v) << " is not 2-bit";
    return 0;
  };
  std::vector<unsigned char> packed(raw.size() / 4);
  for (std::size_t i = 0; i < packed.size(); ++i)
    for (std::size_t k = 0; k < 4; ++k)
      packed[i] = static_cast<unsigned char>(packed[i] | code(static_cast<signed char>(raw[4 * i + k])) << (2 * k));
  const auto dir = test::scratch_dir();
  write_raw(dir / "pocket.i2", packed);
  const auto want = read_all(path, SampleFormat::i8, {}, 0, 4096);
  const auto got =
      read_all(dir / "pocket.i2", SampleFormat::i2, {TwoBitCoding::sign_magnitude, BitOrder::lsb_first}, 0, 4093);
  ASSERT_EQ(got.size(), want.size());
  EXPECT_TRUE(got == want);
}

}  // namespace
}  // namespace ultratrack::signals
