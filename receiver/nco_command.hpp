// SPDX-License-Identifier: GPL-3.0-or-later
// NcoCommand: what any closed loop (scalar DLL/PLL, vector filter, ultra-tight filter) tells a tracking channel
// about its replica for the next epoch. Rates in chips/s and Hz at baseband (after IF removal); jumps in chips and
// cycles. The channel applies a command at the start of its next epoch and keeps it until the next command.
#pragma once

namespace ultratrack::receiver {

struct NcoCommand {
  // Replica code rate including code Doppler, chips/s (nominal 1.023e6). Valid range (0, 2e6].
  double code_rate_chips_per_s = 1.023e6;
  // Replica carrier frequency at baseband, Hz (Doppler plus any residual IF). |f| < fs/2.
  double carrier_frequency_hz = 0.0;
  // One-off phase corrections applied at the start of the next epoch, then consumed (0 = none).
  // Positive code jump advances the replica code (it reaches each chip earlier); |jump| < 511 chips.
  double code_phase_jump_chips = 0.0;
  double carrier_phase_jump_cycles = 0.0;
};

}  // namespace ultratrack::receiver
