// An output file that is written completely or not at all: the content goes to "<path>.partial" and
// commit() flushes and renames it to <path>. Destroying an uncommitted AtomicFile removes the partial
// file, so an error or an interrupted run never leaves a half-written output under the final name.
#pragma once

#include <filesystem>
#include <fstream>

namespace ultratrack::signals {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return stream_; }
  const std::filesystem::path& path() const { return path_; }
  // Flushes, closes and renames; throws InputError (naming the file) when any write failed.
  void commit();

 private:
  std::filesystem::path path_, partial_path_;
  std::ofstream stream_;
  bool committed_ = false;
};

}  // namespace ultratrack::signals
