// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/whole_number.hpp"

#include <cmath>
#include <sstream>

#include "io/input_error.hpp"

namespace ultratrack::io {

int whole_number_field(double value, int lo, int hi, const std::string& file, int line, const std::string& column) {
  // The comparisons are false for NaN, so NaN fails here too.
  if (!(value >= lo && value <= hi && value == std::floor(value))) {
    std::ostringstream problem;
    problem << column << " must be a whole number in [" << lo << ", " << hi << "], got " << value;
    throw InputError(file, problem.str(), line);
  }
  return static_cast<int>(value);
}

}  // namespace ultratrack::io
