#include "ins/atomic_file.hpp"

#include <system_error>

#include "ins/ins_error.hpp"

namespace ultratrack::ins {

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)) {
  tmp_ = path_;
  tmp_ += ".tmp";
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) throw InputError(path_.string(), "cannot create output file");
}

AtomicFile::~AtomicFile() {
  if (f_) {
    std::fclose(f_);
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::write(std::string_view text) {
  if (std::fwrite(text.data(), 1, text.size(), f_) != text.size()) throw InputError(path_.string(), "write failed");
}

void AtomicFile::commit() {
  const bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  std::fclose(f_);
  f_ = nullptr;
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(tmp_, ec);
    throw InputError(path_.string(), "write failed");
  }
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw InputError(path_.string(), "cannot rename temporary file: " + ec.message());
}

}  // namespace ultratrack::ins
