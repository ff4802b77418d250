// SPDX-License-Identifier: GPL-3.0-or-later
// Everything a receive pipeline (pipelines/receiver_pipeline.hpp) needs to know before the first sample: the
// receiver's options, the coupling, the vector filter's carrier mode, and for the GNSS/INS couplings the filter,
// the alignment, the navigation settings and the IMU's time origin; for ultra-tight the measurement form and
// whether the loop runs pipelined; for vector and ultra-tight the windowed NIS release test. Validated once with
// IsValid (as ceres' Options).
#pragma once

#include <string>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"
#include "fusion/ultratight_integration.hpp"
#include "fusion/vector_tracking.hpp"
#include "ins/odometer.hpp"
#include "pipelines/coupling.hpp"
#include "pipelines/fuse_config.hpp"
#include "pipelines/imu_time_line.hpp"
#include "pipelines/navigation_initialisation.hpp"
#include "receiver/receiver_options.hpp"

namespace ultratrack::pipelines {

struct ReceiveOptions {
  receiver::ReceiverOptions receiver;
  Coupling coupling = Coupling::kScalar;
  // kVector: how the vector filter closes the carrier (aided-pll, fll, pll).
  fusion::VectorCarrier vector_carrier = fusion::VectorCarrier::kAidedPll;

  // kLoose, kTight, kUltraTight.
  fusion::FilterKind filter = fusion::FilterKind::Ekf;
  AlignMode align = AlignMode::Motion;  // Static, Motion or Config (Attitude is `fuse`'s)
  FuseConfig navigation;                // `fuse`'s configuration keys
  ImuTimeOrigin imu_time_origin;
  std::string imu_name = "IMU data";  // names the IMU data in errors and summary.json (the file's path)
  // kLoose, kTight: odometer rows (empty: no odometer aiding; `fuse --odometer`'s VMS/NHC updates, [odometer] keys) and
  // the name of their file for errors and summary.json.
  std::vector<ins::OdometerSample> odometer;
  std::string odometer_name = "odometer data";

  // kUltraTight. Serial (the default since 2026-11-29): the loop runs on the caller between blocks, its commands at
  // the epoch that produced them. Pipelined: it runs beside the next block's correlation
  // (receiver::ReceiverEngine::set_vector_loop), its commands one 20 ms vector epoch later, as a real-time receiver
  // may run its navigation filter concurrently with the correlators: ~17 % faster with 2 threads, but that period
  // of delay in the common clock loop (receiver/common_clock_loop.hpp) rings with the channels' 100 ms PLLs on a
  // TCXO (docs/validation.md, section 16), and weak files were lost whole to it.
  fusion::UltraTightForm ut_form = fusion::UltraTightForm::Iq;
  bool ut_pipelined = false;
  // kUltraTight: the common clock loop's noise bandwidth (receiver/common_clock_loop.hpp; --ut-clock-loop-bw), Hz,
  // in (0, 12.5]; 0: off (each channel's PLL follows the receiver oscillator alone).
  double ut_clock_loop_bw_hz = 5.0;
  // kVector, kUltraTight: the windowed NIS test that releases channels (and re-opens or resets the filter):
  // --nis-window, --nis-probability (fusion/nis_release.hpp).
  fusion::NisReleaseOptions nis_release;

  // True when the options fit together; otherwise false and *error (when given) says why, naming the setting as
  // the configuration file or the command line calls it.
  bool IsValid(std::string* error) const;
};

}  // namespace ultratrack::pipelines
