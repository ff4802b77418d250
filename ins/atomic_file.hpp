// An output file written completely or not at all: text goes to "<path>.tmp", commit() renames it onto
// the final path; a writer destroyed without commit() removes the temporary file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace ultratrack::ins {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path);  // throws InputError when the file cannot be created
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* handle() { return f_; }
  void write(std::string_view text);
  void commit();  // flush, close, rename; throws InputError on I/O failure

 private:
  std::filesystem::path path_, tmp_;
  std::FILE* f_ = nullptr;
};

}  // namespace ultratrack::ins
