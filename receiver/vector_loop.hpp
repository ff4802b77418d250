// SPDX-License-Identifier: GPL-3.0-or-later
// The seam for an external (vector) loop: at fixed sample boundaries (the vector epochs) the receiver engine hands
// a VectorLoop every channel's latest correlation results, as pseudorange and Doppler measurements on the
// receiver's clock, and the replica's state; the loop answers one VectorChannelCommand per channel, which the
// channel applies through its NcoCommand at the start of its next epoch (code rate and a code phase jump; the
// carrier either stays with the channel's Costas PLL, aided by the loop's predicted Doppler (CarrierControl::kAided),
// or is the loop's: a vector FLL (kFrequency), or a vector PLL whose phase the loop closes through
// carrier_phase_jump_cycles (kFrequencyAndPhase)). Units: metres, m/s, Hz, chips, samples; C/N0 in dB-Hz.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "receiver/carrier_control.hpp"
#include "receiver/pvt.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

// One channel as the engine sees it at a vector epoch.
struct VectorChannelInput {
  int slot = 0;
  int prn = 0;
  // Bit-synced (20 ms epochs), not lost, frame-synced with a transmit-time tag whose week is known: the replica's
  // pseudorange can be formed. A channel that is not synchronised must be left scalar (VectorChannelCommand{}).
  bool synchronised = false;
  bool vector_mode = false;  // its code loop is closed by the VectorLoop now
  // Lock lost in vector mode: the replica follows the loop's commands alone (no measurements) until the signal
  // returns and the channel re-locks, or the loop stops commanding it (it is then released as lost).
  bool coasting = false;
  double cn0_dbhz = NAN;  // NaN before the first estimate

  // The replica at the epoch's sample: its pseudorange c (t_rx - t_tx) by the receiver clock and its code rate.
  double replica_pseudorange_m = 0.0;
  double code_rate_chips_per_s = 0.0;
  double carrier_frequency_hz = 0.0;
  // Receiver sample at which a command given now takes effect (the channel's next epoch start, >= the epoch's
  // sample).
  std::int64_t next_epoch_sample = 0;

  // The latest correlation epoch completed since the previous vector epoch (has_measurement false: none).
  bool has_measurement = false;
  std::int64_t measurement_sample = 0;  // the middle of that correlation epoch
  double integration_time_s = 0.0;
  double code_error_chips = 0.0;           // early-minus-late discriminator: signal minus replica code phase
  double replica_pseudorange_mid_m = 0.0;  // the replica's pseudorange at measurement_sample
  double measured_pseudorange_m = 0.0;     // replica - code error x chip length
  // Carrier Doppler over the two latest contiguous epochs (middle to middle): the replica's mean frequency plus
  // the Costas phase change, or, for a filter-driven channel whose carrier the loop commands with both epochs'
  // bits known, the phase change with the bits wiped (doppler_bits_wiped; wiped_phase_change_cycles: twice the
  // range, no pull toward 0 below ~24 dB-Hz). Centred at doppler_sample; absent before two contiguous 20 ms epochs.
  bool has_doppler = false;
  double measured_doppler_hz = 0.0;
  std::int64_t doppler_sample = 0;
  double doppler_interval_s = 0.0;  // middle-to-middle time of the two epochs
  bool doppler_bits_wiped = false;
  // The same correlation epoch for a loop that updates from correlations (ultra-tight): its first sample, the
  // replica carrier's mean frequency over it (Hz), and the early/prompt/late I and Q of the master antenna
  // normalised to unit noise variance per I or Q (by the noise tap's running mean power), data bit not removed.
  std::int64_t measurement_first_sample = 0;
  double replica_carrier_frequency_hz = 0.0;
  std::array<double, 3> iq_i{}, iq_q{};  // early, prompt, late
  // The taps above (and iq_scale) are also filled for a new, valid, bit-synced 20 ms-class epoch that the fade gate
  // kept from being a measurement (has_prompt true, has_measurement false): after a step down to ~20 dB-Hz the gate
  // drops most epochs until the channel's presence window reads the new level (up to 1 s), while a loop that
  // combines many channels' prompts (receiver/common_clock_loop.hpp) still needs them. has_measurement implies
  // has_prompt.
  bool has_prompt = false;
  double prompt_integration_time_s = 0;  // that epoch's length (integration_time_s is set with has_measurement only)
  // The replica carrier's accumulated phase (cycles, the NCO's: +Doppler, jumps included) at measurement_sample,
  // and the phase it will have at next_epoch_sample if left on its current command (no new jump): a loop that
  // closes the carrier phase (vector PLL) commands the jump between what it wants there and this.
  double replica_carrier_phase_mid_cycles = 0.0;
  double replica_carrier_phase_next_cycles = 0.0;
  // The factor the taps were multiplied by (1 / the running noise sigma per I or Q; 0: no noise estimate yet). That
  // estimate moves by +-16 % in power (a 0.05 average of one noise tap per epoch), and the normalised signal
  // amplitude with it: a loop estimating the amplitude averages it on the raw scale (taps / iq_scale).
  double iq_scale = 0.0;
  // The navigation bit of that epoch when known ahead (data wipe-off, filter-driven channels only): the sign
  // (+1/-1, polarity applied) that makes the prompt's in-phase positive; 0: unknown.
  int bit_sign = 0;
  // The channel PLL's coherent integration now, in 20 ms epochs (N x 20 ms with data wipe-off; 1 otherwise): its
  // bandwidth, and so its residual phase at an epoch's start, follow N (scalar_tracking.hpp).
  int pll_coherent_epochs = 1;
};

struct VectorEpochInput {
  std::int64_t sample = 0;  // the vector epoch, receiver sample index
  double fs_hz = 0.0;
  signals::GpsTime receive_time;  // by the receiver clock at `sample`
  // Sum of the clock jumps the engine applied so far (ReceiverClock::correct): pseudoranges of later epochs are
  // c x this shorter than before the jumps.
  double clock_corrections_s = 0.0;
  const std::vector<signals::Ephemeris>* ephemerides = nullptr;  // all known (supplied + decoded)
  const signals::KlobucharParameters* iono = nullptr;
  const PvtSolution* last_fix = nullptr;      // nullptr before the first fix
  double last_fix_clock_corrections_s = 0.0;  // clock_corrections_s when last_fix was solved (before its jump)
  std::span<const VectorChannelInput> channels;
  // The sample at which the engine hands the answered commands to the channels: `sample` (the loop runs between
  // blocks: each command takes effect at the channel's next_epoch_sample) or, for a pipelined loop
  // (ReceiverEngine::set_vector_loop), the next vector epoch: the command then takes effect at the channel's first
  // epoch start at or after command_sample, one channel epoch after next_epoch_sample, where the command of the
  // previous vector epoch takes effect first.
  std::int64_t command_sample = 0;
};

// What the loop tells one channel. vector false: the channel's own DLL closes its code loop (scalar).
struct VectorChannelCommand {
  bool vector = false;
  double code_rate_chips_per_s = 0.0;  // including code Doppler
  double code_phase_jump_chips = 0.0;  // applied once at next_epoch_sample; positive advances the replica
  // The predicted carrier Doppler at next_epoch_sample, Hz: an aid to the channel's PLL (kAided) or the carrier
  // NCO's frequency (kFrequency, kFrequencyAndPhase). NaN: no aiding (and with kFrequency*: the channel's own loop).
  double carrier_frequency_hz = NAN;
  CarrierControl carrier = CarrierControl::kAided;
  double carrier_phase_jump_cycles = 0.0;  // kFrequencyAndPhase only
  // The loop judges the channel's carrier phase not to follow the signal now (an aided PLL run away from the
  // predicted Doppler, or just stepped back onto it: pipelines/ultratight_loop.hpp, fusion/false_lock_monitor.hpp): the
  // channel's next measurement carries the loss-of-lock flag (RINEX LLI, Hatch smoother restart), as a cycle slip.
  bool carrier_slip = false;
  // The loop's filter drives the replica and judges lock (ultra-tight): the channel's scalar loss test gives way
  // to the presence test (ScalarTracking::set_filter_driven), its PLL sums N x 20 ms with the known bits wiped
  // (pure PLL; with a commanded carrier there is no PLL, and the known bits wipe the frequency discriminator's
  // epochs instead), and its epochs are handed over without the per-epoch fade gate (with their known bit_sign).
  bool filter_driven = false;
  // The loop adds a common clock loop's frequency (receiver/common_clock_loop.hpp) to this channel's carrier aid
  // (kAided): the channel's PLL chooses its coherent time as if its oscillator were perfect
  // (ScalarTrackingControl::clock_steered).
  bool clock_steered = false;
};

class VectorLoop {
 public:
  virtual ~VectorLoop() = default;
  // Called on the engine's caller thread at every vector epoch with every occupied channel (in slot order);
  // `commands` has one entry per input channel, default-initialised (scalar). A pipelined loop is called while
  // the worker threads correlate the next block: the inputs are copies, and it must touch nothing the engine or
  // the channels use.
  virtual void update(const VectorEpochInput& epoch, std::span<VectorChannelCommand> commands) = 0;
};

}  // namespace ultratrack::receiver
