#include "receiver/fftw_plan.hpp"

#include <cassert>
#include <cstring>
#include <new>
#include <utility>

namespace ultratrack::receiver {

std::mutex& fftw_planner_mutex() {
  static std::mutex mutex;
  return mutex;
}

FftwBuffer::FftwBuffer(std::size_t n) : size_(n) {
  data_ = static_cast<std::complex<float>*>(fftwf_malloc(sizeof(std::complex<float>) * (n == 0 ? 1 : n)));
  if (!data_) throw std::bad_alloc();
  std::memset(static_cast<void*>(data_), 0, sizeof(std::complex<float>) * n);
}

FftwBuffer::~FftwBuffer() { fftwf_free(data_); }

FftwBuffer::FftwBuffer(FftwBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}

FftwBuffer& FftwBuffer::operator=(FftwBuffer&& other) noexcept {
  if (this != &other) {
    fftwf_free(data_);
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

FftwPlan::FftwPlan(std::size_t n, Direction direction) : size_(n) {
  // FFTW new-array execute needs arrays with the planning arrays' alignment and in-place-ness: we plan
  // out of place on fftwf_malloc'ed arrays, which every FftwBuffer matches.
  FftwBuffer in(n), out(n);
  std::lock_guard lock(fftw_planner_mutex());
  plan_ = fftwf_plan_dft_1d(static_cast<int>(n), reinterpret_cast<fftwf_complex*>(in.data()),
                            reinterpret_cast<fftwf_complex*>(out.data()),
                            direction == Direction::forward ? FFTW_FORWARD : FFTW_BACKWARD, FFTW_ESTIMATE);
  if (!plan_) throw std::bad_alloc();
}

FftwPlan::~FftwPlan() {
  if (plan_) {
    std::lock_guard lock(fftw_planner_mutex());
    fftwf_destroy_plan(plan_);
  }
}

FftwPlan::FftwPlan(FftwPlan&& other) noexcept
    : plan_(std::exchange(other.plan_, nullptr)), size_(std::exchange(other.size_, 0)) {}

FftwPlan& FftwPlan::operator=(FftwPlan&& other) noexcept {
  if (this != &other) {
    if (plan_) {
      std::lock_guard lock(fftw_planner_mutex());
      fftwf_destroy_plan(plan_);
    }
    plan_ = std::exchange(other.plan_, nullptr);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

void FftwPlan::execute(const FftwBuffer& in, FftwBuffer& out) const {
  assert(plan_ && in.size() == size_ && out.size() == size_ && in.data() != out.data());
  fftwf_execute_dft(plan_, reinterpret_cast<fftwf_complex*>(const_cast<std::complex<float>*>(in.data())),
                    reinterpret_cast<fftwf_complex*>(out.data()));
}

}  // namespace ultratrack::receiver
