// SPDX-License-Identifier: GPL-3.0-or-later
// An output file that is written completely or not at all: the content goes to "<path>.partial" and
// commit() flushes and renames it to <path>. Destroying an uncommitted AtomicFile removes the partial
// file, so an error or an interrupted run never leaves a half-written output under the final name.
#pragma once

#include <filesystem>
#include <fstream>
#include <string_view>

namespace ultratrack::io {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path, bool binary = false);  // InputError if it cannot be created
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return stream_; }
  void write(std::string_view text) { stream_.write(text.data(), static_cast<std::streamsize>(text.size())); }
  const std::filesystem::path& path() const { return path_; }
  // Flushes, closes and renames; throws InputError (naming the file) when any write failed.
  void commit();

 private:
  std::filesystem::path path_, partial_path_;
  std::ofstream stream_;
  bool committed_ = false;
};

// The whole content in one go, through an AtomicFile.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace ultratrack::io
