// SPDX-License-Identifier: GPL-3.0-or-later
// A scenario as the inputs of the models that simulate it: the antennas' motion (signals' ReceiverMotion),
// the trajectory and IMU errors (ins/), the IF synthesiser's options (signals/). Each throws io::InputError
// naming the scenario file (or the file it reads) when the scenario is not usable.
#pragma once

#include <memory>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/truth_interpolator.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/receiver_motion.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario.hpp"

namespace ultratrack::sim {

// The antennas' motion: InsTruthMotion on `truth` with the scenario's lever arms for an inertial scenario
// (truth required then), else the static position(s) (ENU offsets from llh_deg_m) or the trajectory file.
std::shared_ptr<const signals::ReceiverMotion> make_motion(
    const Scenario& scenario, std::shared_ptr<const ins::TruthInterpolator> truth = nullptr);
// The trajectory and IMU errors of an inertial scenario.
ins::TrajectorySpec trajectory_spec(const Scenario& scenario);
ins::ImuErrorSpec imu_error_spec(const Scenario& scenario);
// Automatic gain: noise plus signals at RMS = full scale / 4 per component of the scenario's sample format.
signals::SynthesiserOptions synthesiser_options(const Scenario& scenario, const NavigationSource& nav);

}  // namespace ultratrack::sim
