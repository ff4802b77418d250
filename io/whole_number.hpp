// SPDX-License-Identifier: GPL-3.0-or-later
// A numeric field of an input file that must be a whole number in a range (a GPS week, a satellite count), checked
// before it becomes an int: converting a double outside int's range (or NaN) is undefined behaviour, so a reader
// that casts first can turn a corrupt line into anything. Bad input gives io::InputError naming the file, the line
// and the column.
#pragma once

#include <string>

namespace ultratrack::io {

// The largest GPS week a reader accepts: weeks count from 1980-01-06, so 9999 is the year 2171.
inline constexpr int kMaxGpsWeek = 9999;

// value as an int when it is a whole number in [lo, hi]; otherwise InputError(file, "<column> must be a whole
// number in [lo, hi], got ...", line).
int whole_number_field(double value, int lo, int hi, const std::string& file, int line, const std::string& column);

}  // namespace ultratrack::io
