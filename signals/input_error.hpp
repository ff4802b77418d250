// SPDX-License-Identifier: GPL-3.0-or-later
// signals' name for the edge exception (io/input_error.hpp): a file, optionally a line, and the problem.
#pragma once

#include "io/input_error.hpp"

namespace ultratrack::signals {
using InputError = io::InputError;
}
