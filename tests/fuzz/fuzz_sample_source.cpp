// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: IF sample files in every format (receiver/sample_source.hpp), the 2-bit packings included. The
// first two bytes pick the format, the 2-bit coding and order, I/Q swap and Q negation, real or complex; the rest is
// the file, read to its end in blocks (float and int16 paths alternately).
#include <complex>
#include <vector>

#include "fuzz_input.hpp"
#include "receiver/sample_source.hpp"
#include "signals/sample_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  if (size < 2) return 0;
  constexpr signals::SampleFormat kFormats[] = {
      signals::SampleFormat::i8,  signals::SampleFormat::i16, signals::SampleFormat::f32, signals::SampleFormat::r8,
      signals::SampleFormat::r16, signals::SampleFormat::r2,  signals::SampleFormat::i2};
  const signals::SampleFormat format = kFormats[data[0] % 7];
  receiver::SampleSourceOptions o;
  o.fs_hz = 4.0e6;
  const bool real = format == signals::SampleFormat::r8 || format == signals::SampleFormat::r16 ||
                    format == signals::SampleFormat::r2;
  o.if_hz = real ? 1.0e6 : 0.0;
  o.iq_swap = !real && (data[1] & 1);
  o.q_negate = data[1] & 2;
  o.two_bit.coding = static_cast<signals::TwoBitCoding>((data[1] >> 2) % 4);
  o.two_bit.order = (data[1] & 16) ? signals::BitOrder::msb_first : signals::BitOrder::lsb_first;
  o.start_sample = (data[1] >> 5);
  const auto file = fuzz::as_file(data + 2, size - 2, "samples.bin");
  fuzz::expect_input_error_or_success([&] {
    receiver::SampleSource source(file, format, o);
    std::vector<std::complex<float>> block(1000);
    std::vector<std::complex<std::int16_t>> block16(777);
    for (int i = 0; i < 10000; ++i) {
      const auto got = (i % 2) ? source.read(block16) : source.read(block);
      if (got.count == 0) break;
    }
  });
  return 0;
}
