// SPDX-License-Identifier: GPL-3.0-or-later
// Who closes a tracking channel's carrier: its own PLL or an external (vector) loop. The one carrier-control
// setting of the seam (VectorChannelCommand::carrier) and of the channel (ScalarTrackingControl::carrier), so that
// a phase-locked carrier without a commanded frequency cannot be written.
#pragma once

namespace ultratrack::receiver {

enum class CarrierControl {
  // The channel's Costas PLL; carrier_frequency_hz aids it (its change from one command to the next is added to the
  // PLL: ScalarTrackingControl::aid).
  kAided,
  // Vector FLL: carrier_frequency_hz (finite) is the carrier NCO's frequency from the next epoch start on, not an
  // aid; the channel runs no carrier loop of its own (ScalarTrackingControl::carrier): the loop closes the
  // carrier through the channel's frequency discriminator (measured_doppler_hz), the channel's bits are detected
  // differentially, its lock test is the C/N0 alone (the presence test when filter_driven too), and its carrier
  // phase is reported with loss of lock (the NCO's accumulated Doppler, not a phase-locked observable).
  kFrequency,
  // Vector PLL: as kFrequency, and the loop also closes the carrier phase: carrier_phase_jump_cycles (positive
  // advances the replica carrier) is applied once at next_epoch_sample, on top of carrier_frequency_hz; the channel
  // detects its bits coherently (Costas: polarity from the preamble) and reports its carrier phase as locked (no
  // RINEX loss-of-lock flag, except on the first epoch after unlocked ones).
  kFrequencyAndPhase,
};

}  // namespace ultratrack::receiver
