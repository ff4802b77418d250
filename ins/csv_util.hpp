// Small CSV helpers shared by the ins readers: trimming, header checks and strict numeric rows
// (every field present, a finite number, nothing left over). Errors throw InputError(file, line).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ultratrack::ins {

std::string_view trim(std::string_view s);
void check_header(const std::string& file, int line, std::string_view text, const std::vector<std::string>& names);
void parse_row(const std::string& file, int line, std::string_view text, std::span<double> out);

template <std::size_t N>
void parse_row(const std::string& file, int line, std::string_view text, std::array<double, N>& out) {
  parse_row(file, line, text, std::span<double>(out.data(), N));
}

}  // namespace ultratrack::ins
