#include "signals/sample_format.hpp"

namespace ultratrack::signals {

std::optional<SampleFormat> parse_sample_format(std::string_view name) {
  if (name == "i8") return SampleFormat::i8;
  if (name == "i16") return SampleFormat::i16;
  if (name == "f32") return SampleFormat::f32;
  if (name == "r8") return SampleFormat::r8;
  if (name == "r16") return SampleFormat::r16;
  return std::nullopt;
}

std::string_view to_string(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
      return "i8";
    case SampleFormat::i16:
      return "i16";
    case SampleFormat::f32:
      return "f32";
    case SampleFormat::r8:
      return "r8";
    case SampleFormat::r16:
      return "r16";
  }
  return "?";
}

bool is_complex(SampleFormat format) {
  return format == SampleFormat::i8 || format == SampleFormat::i16 || format == SampleFormat::f32;
}

std::size_t bytes_per_sample(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
      return 2;
    case SampleFormat::i16:
      return 4;
    case SampleFormat::f32:
      return 8;
    case SampleFormat::r8:
      return 1;
    case SampleFormat::r16:
      return 2;
  }
  return 1;
}

double full_scale(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
    case SampleFormat::r8:
      return 127.0;
    case SampleFormat::i16:
    case SampleFormat::r16:
      return 32767.0;
    case SampleFormat::f32:
      return 1.0;
  }
  return 1.0;
}

}  // namespace ultratrack::signals
