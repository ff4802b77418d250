// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/pull_in.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

PullIn::PullIn(const ScalarTrackingOptions& options, double initial_frequency_hz)
    : opt_(options), initial_frequency_hz_(initial_frequency_hz) {
  const bool search = opt_.pullin_search_hz > 0.0;
  search_end_s_ = search ? opt_.pullin_search_time_s : 0.0;
  wide_end_s_ = search_end_s_ + (search ? 0.0 : opt_.fll_wide_time_s);
  narrow_end_s_ = wide_end_s_ + (search ? 0.0 : opt_.fll_narrow_time_s);
  pll_start_s_ = narrow_end_s_ + opt_.fll_fine_time_s;
}

PullInStage PullIn::stage(double time_s) const {
  if (time_s <= search_end_s_) return PullInStage::kSearch;
  if (time_s <= wide_end_s_) return PullInStage::kWideFll;
  if (time_s <= narrow_end_s_) return PullInStage::kNarrowFll;
  if (time_s <= pll_start_s_) return PullInStage::kFineFll;
  return PullInStage::kPll;
}

double PullIn::frequency_error_hz(const CorrelationEpoch& e, double time_s) {
  const double t = e.integration_time_s;
  const std::complex<float> prompt = e.master().prompt;
  const bool wide_fll = (time_s > search_end_s_ && time_s <= wide_end_s_) || previous_t_s_ == 0.0;
  if (wide_fll != wide_fll_) fll_average_ = {};
  wide_fll_ = wide_fll;
  CrossDot cd = wide_fll ? cross_dot(e.prompt_halves[0], e.prompt_halves[1]) : cross_dot(previous_prompt_, prompt);
  if (!wide_fll && cd.dot < 0.0) cd = {-cd.cross, -cd.dot};
  constexpr double kFllAverage = 0.25;
  fll_average_.cross += kFllAverage * (cd.cross - fll_average_.cross);
  fll_average_.dot += kFllAverage * (cd.dot - fll_average_.dot);
  const double fll_dt = wide_fll ? 0.5 * t : 0.5 * (previous_t_s_ + t);
  const double error_hz = std::atan2(fll_average_.cross, fll_average_.dot) / (kTwoPi * fll_dt);
  previous_prompt_ = prompt;
  previous_t_s_ = t;
  return error_hz;
}

double PullIn::step(PullInStage stage, const CorrelationEpoch& e, double time_s, CarrierLoopFilter& carrier,
                    double* frequency_error_hz) {
  const double t = e.integration_time_s;
  switch (stage) {
    case PullInStage::kSearch: {
      // hold the acquisition's frequency and buffer the prompts; estimate the offset at the stage's end
      if (e.num_code_periods == 1 && search_count_ < kMaxSearchEpochs)
        search_prompts_[static_cast<std::size_t>(search_count_++)] = e.master().prompt;
      double f = initial_frequency_hz_;
      if (time_s + t > search_end_s_) {  // the next epoch belongs to the fine FLL
        f = initial_frequency_hz_ + search_frequency_offset_hz();
        *frequency_error_hz = f - initial_frequency_hz_;
        carrier.reset(f, 0.0);
      }
      return f;
    }
    case PullInStage::kWideFll:
    case PullInStage::kNarrowFll:
      return carrier.update_fll_only(*frequency_error_hz,
                                     stage == PullInStage::kWideFll ? opt_.fll_bw_hz : opt_.fll_narrow_bw_hz, t);
    case PullInStage::kFineFll:
      return fine_fll(e.master().prompt, t, carrier, frequency_error_hz);
    case PullInStage::kPll:
      break;
  }
  return carrier.frequency_hz();
}

// The frequency offset of the buffered 1 ms prompts (carrier held constant while they were taken): argmax over a
// 2.5 Hz grid of the energy of 10 ms coherent blocks summed over blocks (a block holding a bit edge loses
// coherence but keeps its energy near the true offset), refined by a parabola through the peak and neighbours.
double PullIn::search_frequency_offset_hz() const {
  constexpr int kBlock = 10;
  constexpr double kStep_hz = 2.5;
  const int blocks = search_count_ / kBlock;
  if (blocks == 0) return 0.0;
  const int half = static_cast<int>(std::ceil(opt_.pullin_search_hz / kStep_hz));
  const auto energy = [&](double f_hz) {
    const std::complex<double> step = std::polar(1.0, -kTwoPi * f_hz * 1e-3);
    std::complex<double> rotation = 1.0;
    double sum = 0.0;
    for (int b = 0; b < blocks; ++b) {
      std::complex<double> block{};
      for (int k = 0; k < kBlock; ++k) {
        block +=
            std::complex<double>(search_prompts_[static_cast<std::size_t>(b) * kBlock + static_cast<std::size_t>(k)]) *
            rotation;
        rotation *= step;
      }
      sum += std::norm(block);
    }
    return sum;
  };
  int best = 0;
  double best_e = -1.0, previous_e = 0.0, before_best = 0.0, after_best = 0.0;
  bool need_after = false;
  for (int i = -half; i <= half; ++i) {
    const double e = energy(i * kStep_hz);
    if (need_after) {
      after_best = e;
      need_after = false;
    }
    if (e > best_e) {
      best_e = e;
      best = i;
      before_best = previous_e;
      need_after = true;
    }
    previous_e = e;
  }
  if (best == -half || best == half) return best * kStep_hz;  // at the edge of the range: no parabola
  const double den = before_best - 2.0 * best_e + after_best;
  const double delta = den < 0.0 ? std::clamp(0.5 * (before_best - after_best) / den, -0.5, 0.5) : 0.0;
  return (best + delta) * kStep_hz;
}

double PullIn::fine_fll(std::complex<float> prompt, double t_s, CarrierLoopFilter& carrier,
                        double* frequency_error_hz) {
  constexpr int kFineSumEpochs = 5;  // 5 ms sums: +-50 Hz range, at most one bit edge inside (bit-tolerant)
  fine_sum_ += std::complex<double>(prompt);
  fine_time_s_ += t_s;
  if (++fine_count_ < kFineSumEpochs) return carrier.frequency_hz();
  double frequency = carrier.frequency_hz();
  if (fine_have_previous_) {
    const std::complex<float> a(fine_previous_), b(fine_sum_);
    CrossDot cd = cross_dot(a, b);
    if (cd.dot < 0.0) cd = {-cd.cross, -cd.dot};
    *frequency_error_hz = std::atan2(cd.cross, cd.dot) / (kTwoPi * fine_time_s_);
    frequency = carrier.update_fll_only(*frequency_error_hz, opt_.fll_fine_bw_hz, fine_time_s_);
  }
  fine_previous_ = fine_sum_;
  fine_have_previous_ = true;
  fine_sum_ = {};
  fine_count_ = 0;
  fine_time_s_ = 0.0;
  return frequency;
}

}  // namespace ultratrack::receiver
