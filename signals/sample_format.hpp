// SPDX-License-Identifier: GPL-3.0-or-later
// IF sample file formats: how complex baseband (or real IF) samples are laid out in a recording.
//   i8  interleaved int8 I/Q        i16 interleaved int16 I/Q (little endian)
//   f32 interleaved float32 I/Q (GNU Radio gr_complex)
//   r8  real int8                   r16 real int16 (little endian)
//   r2  real 2-bit packed, 4 samples per byte       i2  complex 2-bit packed, 2 I/Q pairs per byte (I, Q, I, Q)
// The 2-bit formats hold the levels -3, -1, +1, +3 (file units); TwoBitLayout says how a 2-bit field codes
// them and where in the byte the first field sits (docs/architecture.md has the table with the peers'
// conventions: GNSS-SDR Two_Bit_Packed_File_Signal_Source, MAX2769/MAX2771, NT1065).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace ultratrack::signals {

enum class SampleFormat { i8, i16, f32, r8, r16, r2, i2 };

// How one 2-bit field (bit 1 = its high bit) codes a level; codes 0b00, 0b01, 0b10, 0b11 give:
//   twos_complement  +1 +3 -3 -1  (the field as a two's complement v, level 2v+1: GNSS-SDR's Two_Bit_Packed
//                                 source, MAX2769 "two's complement")
//   sign_magnitude   +1 +3 -1 -3  (bit 1 sign, 1 = negative; bit 0 magnitude, 1 = 3: MAX2769/MAX2771
//                                 "sign/magnitude", PocketSDR)
//   offset_binary    -3 -1 +1 +3  (MAX2769 "unsigned binary")
//   nt1065           -1 +1 -3 +3  (bit 1 magnitude, 1 = 3; bit 0 sign, 1 = positive: NTLab NT1065 as
//                                 GNSS-SDR's NTLab_File_Signal_Source reads it)
enum class TwoBitCoding { twos_complement, sign_magnitude, offset_binary, nt1065 };
// Where the first sample of a byte sits: lsb_first = bits 1:0 (then 3:2, 5:4, 7:6; GNSS-SDR's default,
// big_endian_bytes = false), msb_first = bits 7:6 (then 5:4, 3:2, 1:0; GNSS-SDR big_endian_bytes = true).
enum class BitOrder { lsb_first, msb_first };

// The level each code 0..3 stands for (the table above).
std::array<int, 4> two_bit_levels(TwoBitCoding coding);

struct TwoBitLayout {
  TwoBitCoding coding = TwoBitCoding::twos_complement;
  BitOrder order = BitOrder::lsb_first;
};

// Parses "i8", "i16", ... ; nothing for an unknown name.
std::optional<SampleFormat> parse_sample_format(std::string_view name);
std::string_view to_string(SampleFormat format);
// Every format name, "i8, i16, f32, r8, r16, r2, i2" (for messages and --help).
std::string_view sample_format_names();
// "twos", "sign-magnitude", "offset-binary", "nt1065"; "lsb-first", "msb-first".
std::optional<TwoBitCoding> parse_two_bit_coding(std::string_view name);
std::string_view to_string(TwoBitCoding coding);
std::string_view two_bit_coding_names();
std::optional<BitOrder> parse_bit_order(std::string_view name);
std::string_view to_string(BitOrder order);
std::string_view bit_order_names();

bool is_complex(SampleFormat format);
bool is_two_bit(SampleFormat format);
// Bits of one sample (one complex pair or one real value): 16, 32, 64, 8, 16, 2, 4.
std::size_t bits_per_sample(SampleFormat format);
// Bytes of one sample for the byte-aligned formats; 0 for the packed 2-bit formats (samples_per_byte).
std::size_t bytes_per_sample(SampleFormat format);
// Whole samples in one byte for the packed formats (r2 4, i2 2); 0 for the byte-aligned ones.
std::size_t samples_per_byte(SampleFormat format);
// The largest magnitude a format holds (127, 32767, 3 for 2-bit); 1.0 for f32 (a nominal scale, not a limit).
double full_scale(SampleFormat format);
// The per-component RMS a writer's input should have: full scale / 4 for the multi-bit formats (clipping
// beyond 4 sigma); 2 for the 2-bit formats, whose quantiser threshold (between levels 1 and 3) is 2: the
// noise sigma there puts the threshold at 1 sigma, the setting of minimum loss (~0.55 dB, see sample_writer).
double nominal_rms(SampleFormat format);

}  // namespace ultratrack::signals
