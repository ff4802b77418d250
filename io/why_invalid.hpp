// SPDX-License-Identifier: GPL-3.0-or-later
// The one idiom of option checking: every Options struct has `bool IsValid(std::string* why) const`, checked once
// at the edge (configuration file, command line, library entry). why_invalid() gives the reason as a string (empty
// when valid), for composing checks and for error messages.
#pragma once

#include <string>

namespace ultratrack::io {

template <typename Options>
std::string why_invalid(const Options& options) {
  std::string why;
  return options.IsValid(&why) ? std::string{} : why;
}

}  // namespace ultratrack::io
