// SPDX-License-Identifier: GPL-3.0-or-later
// Sample file formats: write -> read round trips for every format (exact for representable values,
// rounding and saturation at the integer limits), and the clear errors for broken files.
#include <gtest/gtest.h>

#include <complex>
#include <fstream>
#include <functional>
#include <vector>

#include "signals/input_error.hpp"
#include "signals/sample_format.hpp"
#include "signals/sample_reader.hpp"
#include "signals/sample_writer.hpp"
#include "support/test_data.hpp"

namespace ultratrack::signals {
namespace {

const SampleFormat kAllFormats[] = {SampleFormat::i8, SampleFormat::i16, SampleFormat::f32, SampleFormat::r8,
                                    SampleFormat::r16};

std::vector<std::complex<float>> read_all(const std::filesystem::path& path, SampleFormat format,
                                          std::int64_t start = 0, std::size_t block = 7) {
  SampleReader reader(path, format, start);
  std::vector<std::complex<float>> all, buf(block);
  while (std::size_t n = reader.read(buf)) all.insert(all.end(), buf.begin(), buf.begin() + n);
  return all;
}

void write_bytes(const std::filesystem::path& path, std::size_t n) {
  std::ofstream f(path, std::ios::binary);
  for (std::size_t i = 0; i < n; ++i) f.put(static_cast<char>(i));
}

TEST(SampleFormat, ParsesNamesAndSizes) {
  for (auto f : kAllFormats) EXPECT_EQ(parse_sample_format(to_string(f)), f);
  EXPECT_FALSE(parse_sample_format("u8").has_value());
  EXPECT_EQ(bytes_per_sample(SampleFormat::i8), 2u);
  EXPECT_EQ(bytes_per_sample(SampleFormat::i16), 4u);
  EXPECT_EQ(bytes_per_sample(SampleFormat::f32), 8u);
  EXPECT_EQ(bytes_per_sample(SampleFormat::r8), 1u);
  EXPECT_EQ(bytes_per_sample(SampleFormat::r16), 2u);
  EXPECT_TRUE(is_complex(SampleFormat::f32));
  EXPECT_FALSE(is_complex(SampleFormat::r16));
}

TEST(SampleIo, RoundTripsEveryFormatInBlocks) {
  const auto dir = test::scratch_dir();
  std::vector<std::complex<float>> in;
  for (int i = 0; i < 1000; ++i)
    in.emplace_back(static_cast<float>(i % 255 - 127), static_cast<float>(-(i % 201) + 100));
  for (auto format : kAllFormats) {
    const auto path = dir / ("rt." + std::string(to_string(format)));
    {
      SampleWriter w(path, format);
      w.write(std::span(in).first(333));
      w.write(std::span(in).subspan(333));
      w.finish();
    }
    const auto out = read_all(path, format);
    ASSERT_EQ(out.size(), in.size()) << to_string(format);
    for (std::size_t i = 0; i < in.size(); ++i) {
      EXPECT_EQ(out[i].real(), in[i].real()) << to_string(format) << " sample " << i;
      EXPECT_EQ(out[i].imag(), is_complex(format) ? in[i].imag() : 0.0f) << to_string(format) << " sample " << i;
    }
    EXPECT_EQ(std::filesystem::file_size(path), in.size() * bytes_per_sample(format));
  }
}

TEST(SampleIo, RoundsAndSaturatesIntegerFormats) {
  const auto dir = test::scratch_dir();
  const std::vector<std::complex<float>> in = {{1.4f, -1.6f}, {2.5f, -2.5f}, {300.0f, -300.0f}, {1e6f, -1e6f}};
  {
    SampleWriter w(dir / "a.i8", SampleFormat::i8);
    w.write(in);
    w.finish();
  }
  auto out = read_all(dir / "a.i8", SampleFormat::i8);
  EXPECT_EQ(out[0], std::complex<float>(1, -2));
  EXPECT_EQ(out[1], std::complex<float>(3, -3));
  EXPECT_EQ(out[2], std::complex<float>(127, -128));
  {
    SampleWriter w(dir / "a.i16", SampleFormat::i16);
    w.write(in);
    w.finish();
  }
  out = read_all(dir / "a.i16", SampleFormat::i16);
  EXPECT_EQ(out[2], std::complex<float>(300, -300));
  EXPECT_EQ(out[3], std::complex<float>(32767, -32768));
  {
    SampleWriter w(dir / "a.f32", SampleFormat::f32);
    w.write(in);
    w.finish();
  }
  out = read_all(dir / "a.f32", SampleFormat::f32);
  EXPECT_EQ(out[0], in[0]);
  EXPECT_EQ(out[3], in[3]);
}

TEST(SampleIo, ReadsLittleEndianBytesAsDocumented) {
  const auto dir = test::scratch_dir();
  {
    std::ofstream f(dir / "le.i16", std::ios::binary);
    const unsigned char bytes[] = {0x34, 0x12, 0xff, 0xff};  // I = 0x1234, Q = -1
    f.write(reinterpret_cast<const char*>(bytes), 4);
  }
  const auto out = read_all(dir / "le.i16", SampleFormat::i16);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], std::complex<float>(4660, -1));
}

TEST(SampleIo, StartOffsetSkipsSamples) {
  const auto dir = test::scratch_dir();
  std::vector<std::complex<float>> in;
  for (int i = 0; i < 100; ++i) in.emplace_back(static_cast<float>(i), static_cast<float>(-i));
  for (auto format : kAllFormats) {
    const auto path = dir / ("off." + std::string(to_string(format)));
    SampleWriter w(path, format);
    w.write(in);
    w.finish();
    SampleReader r(path, format, 40);
    EXPECT_EQ(r.total_samples(), 100);
    EXPECT_EQ(r.position(), 40);
    const auto out = read_all(path, format, 40, 16);
    ASSERT_EQ(out.size(), 60u);
    EXPECT_EQ(out[0].real(), 40.0f);
    EXPECT_EQ(out[59].real(), 99.0f);
  }
}

TEST(SampleIo, UnfinishedWriterLeavesNoFile) {
  const auto dir = test::scratch_dir();
  {
    SampleWriter w(dir / "gone.i8", SampleFormat::i8);
    std::vector<std::complex<float>> in(10, {1.0f, 1.0f});
    w.write(in);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "gone.i8"));
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// An InputError whose message names the file and contains the given problem text.
void expect_input_error(const std::function<void()>& f, const std::string& file, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << file;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find(text), std::string::npos) << what;
  }
}

TEST(SampleIo, TruncatedFinalSampleIsAnError) {
  const auto dir = test::scratch_dir();
  write_bytes(dir / "t.i16", 4 * 10 + 3);
  expect_input_error([&] { SampleReader r(dir / "t.i16", SampleFormat::i16); }, "t.i16", "truncated");
  write_bytes(dir / "t.f32", 8 * 3 + 4);
  expect_input_error([&] { SampleReader r(dir / "t.f32", SampleFormat::f32); }, "t.f32", "truncated");
  write_bytes(dir / "t.i8", 7);
  expect_input_error([&] { SampleReader r(dir / "t.i8", SampleFormat::i8); }, "t.i8", "truncated");
}

TEST(SampleIo, EmptyOrMissingFileIsAnError) {
  const auto dir = test::scratch_dir();
  write_bytes(dir / "empty.i8", 0);
  expect_input_error([&] { SampleReader r(dir / "empty.i8", SampleFormat::i8); }, "empty.i8", "empty");
  expect_input_error([&] { SampleReader r(dir / "missing.i8", SampleFormat::i8); }, "missing.i8", "does not exist");
}

TEST(SampleIo, StartBeyondTheEndIsAnError) {
  const auto dir = test::scratch_dir();
  write_bytes(dir / "s.r8", 50);
  expect_input_error([&] { SampleReader r(dir / "s.r8", SampleFormat::r8, 50); }, "s.r8", "beyond the end");
  expect_input_error([&] { SampleReader r(dir / "s.r8", SampleFormat::r8, -1); }, "s.r8", "negative");
  SampleReader ok(dir / "s.r8", SampleFormat::r8, 49);
  EXPECT_EQ(ok.total_samples(), 50);
}

}  // namespace
}  // namespace ultratrack::signals
