// Text outputs written completely or not at all: the content goes to a temporary name beside the target
// and is renamed over it once written and closed. Throws InputError naming the file on failure.
#pragma once

#include <filesystem>
#include <string_view>

namespace ultratrack::tools {

void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace ultratrack::tools
