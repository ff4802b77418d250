// SPDX-License-Identifier: GPL-3.0-or-later
// The coupling of a receive run: fusion::Coupling (fusion/coupling.hpp, the one coupling enum of the tree), named
// here as the pipelines use it.
#pragma once

#include "fusion/coupling.hpp"

namespace ultratrack::pipelines {

using fusion::Coupling;
using fusion::coupling_from_string;
using fusion::is_tight;
using fusion::to_string;
using fusion::uses_imu;

}  // namespace ultratrack::pipelines
