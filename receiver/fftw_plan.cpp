// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/fftw_plan.hpp"

#include <cassert>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>
#include <utility>

namespace ultratrack::receiver {

std::mutex& fftw_planner_mutex() {
  static std::mutex mutex;
  return mutex;
}

namespace {

// The wisdom file named by ULTRATRACK_FFTW_WISDOM, imported once per process ("" when unset).
const std::string& wisdom_path() {
  static const std::string path = [] {
    const char* p = std::getenv("ULTRATRACK_FFTW_WISDOM");
    std::string s = p ? p : "";
    std::error_code ec;
    if (!s.empty() && std::filesystem::exists(s, ec))
      fftwf_import_wisdom_from_filename(s.c_str());  // bad file: ignored
    return s;
  }();
  return path;
}

}  // namespace

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
  auto plan = [&](unsigned flags) {
    return fftwf_plan_dft_1d(static_cast<int>(n), reinterpret_cast<fftwf_complex*>(in.data()),
                             reinterpret_cast<fftwf_complex*>(out.data()),
                             direction == Direction::kForward ? FFTW_FORWARD : FFTW_BACKWARD, flags);
  };
  // With a wisdom file: FFTW_PATIENT plans (1.4-2.3x faster transforms at 2600 and 16000 points than
  // FFTW_ESTIMATE, measured, docs/performance.md) from the file, measured once (seconds) and saved when
  // missing. Without one: FFTW_ESTIMATE, instant. The wisdom is a cache, never required.
  const std::string& wisdom = wisdom_path();
  if (!wisdom.empty()) {
    plan_ = plan(FFTW_PATIENT | FFTW_WISDOM_ONLY);
    if (!plan_) {
      plan_ = plan(FFTW_PATIENT);
      if (plan_) {
        const std::string tmp = wisdom + ".tmp" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
        if (fftwf_export_wisdom_to_filename(tmp.c_str())) {
          std::error_code ec;
          std::filesystem::rename(tmp, wisdom, ec);  // atomic replace; a failure leaves the cache as it was
          if (ec) std::filesystem::remove(tmp, ec);
        }
      }
    }
  }
  if (!plan_) plan_ = plan(FFTW_ESTIMATE);
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
