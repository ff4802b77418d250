// SPDX-License-Identifier: GPL-3.0-or-later
// FFTW single-precision 1-D complex transforms with FFTW-aligned buffers. FFTW's planner (plan creation
// and destruction) is not thread-safe: every plan in the receiver is made and destroyed under the one
// process-wide mutex fftw_planner_mutex(); executing a plan on other buffers (new-array execute) is safe.
#pragma once

#include <fftw3.h>

#include <complex>
#include <cstddef>
#include <mutex>

namespace ultratrack::receiver {

// The mutex that serialises every FFTW planner call in the process.
std::mutex& fftw_planner_mutex();

// A buffer of n complex floats allocated with fftwf_malloc (SIMD-aligned), zero-initialised.
class FftwBuffer {
 public:
  FftwBuffer() = default;
  explicit FftwBuffer(std::size_t n);
  ~FftwBuffer();
  FftwBuffer(FftwBuffer&& other) noexcept;
  FftwBuffer& operator=(FftwBuffer&& other) noexcept;
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;

  std::complex<float>* data() { return data_; }
  const std::complex<float>* data() const { return data_; }
  std::size_t size() const { return size_; }
  std::complex<float>& operator[](std::size_t i) { return data_[i]; }
  const std::complex<float>& operator[](std::size_t i) const { return data_[i]; }

 private:
  std::complex<float>* data_ = nullptr;
  std::size_t size_ = 0;
};

// An unnormalised forward (e^{-j...}) or backward (e^{+j...}) DFT of n points, planned with
// FFTW_ESTIMATE (no measuring, so plans are cheap to make), or, when the environment variable
// ULTRATRACK_FFTW_WISDOM names a wisdom file, with FFTW_PATIENT from that file (measured and added on first use).
// execute() may be called on any pair of FftwBuffers of size n (out of place: in and out distinct), from any thread.
class FftwPlan {
 public:
  enum class Direction { kForward, kBackward };
  FftwPlan() = default;
  FftwPlan(std::size_t n, Direction direction);
  ~FftwPlan();
  FftwPlan(FftwPlan&& other) noexcept;
  FftwPlan& operator=(FftwPlan&& other) noexcept;
  FftwPlan(const FftwPlan&) = delete;
  FftwPlan& operator=(const FftwPlan&) = delete;

  std::size_t size() const { return size_; }
  void execute(const FftwBuffer& in, FftwBuffer& out) const;

 private:
  fftwf_plan plan_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace ultratrack::receiver
