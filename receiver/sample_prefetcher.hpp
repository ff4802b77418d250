// SPDX-License-Identifier: GPL-3.0-or-later
// Read-ahead of a SampleSource: while the receiver processes one block, a reader thread reads (and converts)
// the next, so reading the file is off the engine's caller thread. Once told the engine's int16 gain
// (ReceiverEngine::i16_gain), it also converts each block it reads to the planar int16 the integer correlator
// uses (convert_to_planar_i16, the engine's own conversion, so the values are the same whoever converts).
// Deterministic: blocks come out in file order with the same samples whatever the thread timing.
// Units: samples.
#pragma once

#include <atomic>
#include <complex>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "receiver/sample_source.hpp"

namespace ultratrack::receiver {

// One block as read: where it sits, its complex float samples and, when i16_gain > 0, the same samples as
// planar int16 times i16_gain.
struct PrefetchedBlock {
  SampleBlock where;  // count 0: the end
  std::span<const std::complex<float>> samples;
  const std::int16_t* re = nullptr;
  const std::int16_t* im = nullptr;
  float i16_gain = 0.0f;
};

class SamplePrefetcher final {
 public:
  // Reads blocks of block_size samples (the last one shorter) until `limit` samples have been read or the
  // file ends. threaded: read one block ahead on a reader thread; false: read on the caller when asked.
  SamplePrefetcher(SampleSource& source, std::size_t block_size, std::int64_t limit, bool threaded);
  ~SamplePrefetcher();
  SamplePrefetcher(const SamplePrefetcher&) = delete;
  SamplePrefetcher& operator=(const SamplePrefetcher&) = delete;

  // The next block, valid until the next call. Rethrows what the reader threw (signals::InputError).
  PrefetchedBlock next();
  // Blocks read from now on come with planar int16 at this gain too (> 0; the first positive value sticks).
  void set_i16_gain(float gain);

 private:
  struct Slot {
    std::vector<std::complex<float>> samples;
    std::vector<std::int16_t> i16;  // re then im
    SampleBlock where;
    float i16_gain = 0.0f;
    bool ready = false;
  };
  void fill(Slot& slot);  // reads the next block into slot (any thread; the source is used by one at a time)
  void reader_loop();

  SampleSource& source_;
  std::size_t block_size_;
  std::int64_t left_;  // samples still to read
  std::atomic<float> i16_gain_{0.0f};
  Slot slots_[2];
  int consumer_ = -1;  // slot the caller holds (-1: none yet)
  int next_ = 0;       // slot the next block goes to / comes from
  bool threaded_;
  bool stop_ = false, ended_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::thread reader_;
};

}  // namespace ultratrack::receiver
