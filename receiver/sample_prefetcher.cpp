// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/sample_prefetcher.hpp"

#include <algorithm>

#include "receiver/correlator_engine.hpp"

namespace ultratrack::receiver {

SamplePrefetcher::SamplePrefetcher(SampleSource& source, std::size_t block_size, std::int64_t limit, bool threaded)
    : source_(source),
      block_size_(std::max<std::size_t>(1, block_size)),
      left_(std::max<std::int64_t>(0, limit)),
      threaded_(threaded) {
  for (Slot& s : slots_) {
    s.samples.resize(block_size_);
    s.i16.resize(2 * block_size_);
  }
  if (threaded_) reader_ = std::thread([this] { reader_loop(); });
}

SamplePrefetcher::~SamplePrefetcher() {
  if (!reader_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  reader_.join();
}

void SamplePrefetcher::set_i16_gain(float gain) {
  float none = 0.0f;
  if (gain > 0.0f) i16_gain_.compare_exchange_strong(none, gain);
}

void SamplePrefetcher::fill(Slot& slot) {
  const auto want = static_cast<std::size_t>(std::min<std::int64_t>(static_cast<std::int64_t>(block_size_), left_));
  slot.where = SampleBlock{source_.next_sample(), 0};
  slot.i16_gain = i16_gain_.load();
  // In pieces of 16k samples (128 kB of floats), each converted while it is still in cache; the source's
  // output does not depend on how its reads are split (phase-continuous IF removal).
  constexpr std::size_t kPiece = 16384;
  std::int16_t* re = slot.i16.data();
  std::int16_t* im = re + want;  // planar: all I, then all Q, of the samples this block holds
  while (slot.where.count < want) {
    const std::size_t at = slot.where.count;
    const SampleBlock got = source_.read(std::span(slot.samples.data() + at, std::min(kPiece, want - at)));
    if (got.count == 0) break;
    if (slot.i16_gain > 0.0f)
      convert_to_planar_i16(slot.samples.data() + at, static_cast<int>(got.count), slot.i16_gain, re + at, im + at);
    slot.where.count += got.count;
  }
  if (slot.where.count < want && slot.where.count > 0 && slot.i16_gain > 0.0f)  // the file ended early: close up Q
    std::copy(im, im + slot.where.count, re + slot.where.count);
  left_ -= static_cast<std::int64_t>(slot.where.count);
}

void SamplePrefetcher::reader_loop() {
  int r = 0;
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stop_ || (!slots_[r].ready && consumer_ != r); });
    if (stop_) return;
    lock.unlock();
    bool end = false;
    try {
      fill(slots_[r]);
      end = slots_[r].where.count == 0;
    } catch (...) {
      lock.lock();
      error_ = std::current_exception();
      changed_.notify_all();
      return;
    }
    lock.lock();
    slots_[r].ready = true;
    changed_.notify_all();
    if (end) return;
    r ^= 1;
  }
}

PrefetchedBlock SamplePrefetcher::next() {
  if (ended_) return PrefetchedBlock{SampleBlock{source_.next_sample(), 0}, {}, nullptr, nullptr, 0.0f};
  Slot* got = nullptr;
  if (!threaded_) {
    fill(slots_[0]);
    got = &slots_[0];
  } else {
    std::unique_lock lock(mutex_);
    if (consumer_ >= 0) {
      slots_[consumer_].ready = false;  // handed back: the reader may fill it
      consumer_ = -1;
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return slots_[next_].ready || error_ != nullptr; });
    if (!slots_[next_].ready) std::rethrow_exception(error_);  // only after every block read before it
    consumer_ = next_;
    next_ ^= 1;
    got = &slots_[consumer_];
  }
  const std::size_t n = got->where.count;
  if (n == 0) ended_ = true;
  PrefetchedBlock out;
  out.where = got->where;
  out.samples = std::span<const std::complex<float>>(got->samples.data(), n);
  if (got->i16_gain > 0.0f && n > 0) {
    out.re = got->i16.data();
    out.im = got->i16.data() + n;
    out.i16_gain = got->i16_gain;
  }
  return out;
}

}  // namespace ultratrack::receiver
