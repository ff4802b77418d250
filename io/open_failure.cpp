// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/open_failure.hpp"

#include <cerrno>
#include <cstring>

namespace ultratrack::io {

std::string open_failure_reason() {
  const int error = errno;
  return error != 0 ? std::string(std::strerror(error)) : std::string("reason unknown");
}

}  // namespace ultratrack::io
