// SPDX-License-Identifier: GPL-3.0-or-later
// ins' name for the edge exception (io/input_error.hpp): IMU/nav CSV files, profile names, segment files.
#pragma once

#include "io/input_error.hpp"

namespace ultratrack::ins {
using InputError = io::InputError;
}
