// SPDX-License-Identifier: GPL-3.0-or-later
// Why a file could not be opened, for the one-line error of io::InputError ("cannot open ...: Permission
// denied"). Call it right after a failed open of an fstream: libstdc++ opens with open(2), whose errno says
// whether the file is missing, unreadable or a directory; "reason unknown" when errno is 0.
#pragma once

#include <string>

namespace ultratrack::io {

std::string open_failure_reason();

}  // namespace ultratrack::io
