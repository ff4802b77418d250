#include "atomic_file.hpp"

#include <fstream>
#include <string>
#include <system_error>

#include "signals/input_error.hpp"

namespace ultratrack::tools {

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  auto temp = path;
  temp += ".part";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw signals::InputError(path.string(), "cannot create the file");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(temp, ec);
      throw signals::InputError(path.string(), "writing the file failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) throw signals::InputError(path.string(), "cannot rename " + temp.string() + ": " + ec.message());
}

}  // namespace ultratrack::tools
