// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/atomic_file.hpp"

#include <system_error>

#include "io/input_error.hpp"
#include "io/open_failure.hpp"

namespace ultratrack::io {

AtomicFile::AtomicFile(std::filesystem::path path, bool binary)
    : path_(std::move(path)), partial_path_(path_.string() + ".partial") {
  stream_.open(partial_path_,
               binary ? std::ios::out | std::ios::binary | std::ios::trunc : std::ios::out | std::ios::trunc);
  if (!stream_) throw InputError(path_.string(), "cannot open for writing: " + open_failure_reason());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;
  std::filesystem::remove(partial_path_, ignored);
}

void AtomicFile::commit() {
  stream_.flush();
  const bool ok = static_cast<bool>(stream_);
  stream_.close();
  if (!ok) throw InputError(path_.string(), "write failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(partial_path_, path_, ec);
  if (ec) throw InputError(path_.string(), "cannot rename the finished file into place: " + ec.message());
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  AtomicFile file(path);
  file.write(content);
  file.commit();
}

}  // namespace ultratrack::io
