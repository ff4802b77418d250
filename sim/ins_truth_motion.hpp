// SPDX-License-Identifier: GPL-3.0-or-later
// Drives the IF synthesiser from the INS trajectory simulator: antennas fixed on the vehicle at body
// lever arms (m, body axes), moving with the interpolated truth (ins/truth_interpolator.hpp). The
// synthesiser's time (true GPS time since the scenario start) maps to the run's time line as t + t0_s.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "ins/truth_interpolator.hpp"
#include "signals/receiver_motion.hpp"

namespace ultratrack::sim {

class InsTruthMotion final : public signals::ReceiverMotion {
 public:
  InsTruthMotion(std::shared_ptr<const ins::TruthInterpolator> truth, std::vector<Eigen::Vector3d> lever_arms_b,
                 double t0_s = 0.0)
      : truth_(std::move(truth)), lever_arms_b_(std::move(lever_arms_b)), t0_s_(t0_s) {}

  int antenna_count() const override { return static_cast<int>(lever_arms_b_.size()); }
  signals::AntennaState antenna_state(int antenna, double t_s) const override {
    const ins::EcefMotion m = truth_->antenna(t_s + t0_s_, lever_arms_b_[static_cast<std::size_t>(antenna)]);
    return {m.r_e, m.v_e};
  }

 private:
  std::shared_ptr<const ins::TruthInterpolator> truth_;
  std::vector<Eigen::Vector3d> lever_arms_b_;
  double t0_s_;
};

}  // namespace ultratrack::sim
