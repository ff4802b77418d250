// IF sample file formats: how complex baseband (or real IF) samples are laid out in a recording.
//   i8  interleaved int8 I/Q        i16 interleaved int16 I/Q (little endian)
//   f32 interleaved float32 I/Q (GNU Radio gr_complex)
//   r8  real int8                   r16 real int16 (little endian)
// More formats that real front ends record are added here (packed 2-bit etc.).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace ultratrack::signals {

enum class SampleFormat { i8, i16, f32, r8, r16 };

// Parses "i8", "i16", ... ; nothing for an unknown name.
std::optional<SampleFormat> parse_sample_format(std::string_view name);
std::string_view to_string(SampleFormat format);
bool is_complex(SampleFormat format);
// Bytes of one sample (one complex pair or one real value).
std::size_t bytes_per_sample(SampleFormat format);
// The largest magnitude an integer format holds (127, 32767); 1.0 for f32 (a nominal scale, not a limit).
double full_scale(SampleFormat format);

}  // namespace ultratrack::signals
