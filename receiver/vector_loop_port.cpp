// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/vector_loop_port.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ultratrack::receiver {

void VectorLoopPort::set(VectorLoop* loop, double interval_s, bool pipelined, double fs_hz, std::int64_t from_sample,
                         std::vector<std::unique_ptr<ReceiverChannel>>& channels) {
  if (!(interval_s >= 0.001 && interval_s <= 1.0))
    throw std::invalid_argument("ReceiverEngine: vector interval outside [0.001, 1] s");
  if (!loop)
    for (auto& channel : channels)
      if (channel) channel->set_vector_command({});
  loop_ = loop;
  fs_hz_ = fs_hz;
  pipelined_mode_ = pipelined;
  pipelined_.queued = pipelined_.answered = false;
  step_ = std::max<std::int64_t>(1, std::llround(interval_s * fs_hz));
  next_ = from_sample + step_;
}

void VectorLoopPort::finish() {
  if (loop_ && pipelined_.queued) run_pipelined();
  pipelined_.answered = false;
}

std::int64_t VectorLoopPort::next_epoch_after(std::int64_t sample) {
  if (next_ <= sample) next_ += ((sample - next_) / step_ + 1) * step_;  // start, gaps
  return next_;
}

void VectorLoopPort::collect_inputs(std::int64_t sample, const std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                                    const EpochSolver& solver, std::vector<VectorChannelInput>& in,
                                    VectorEpochInput& epoch) {
  const std::optional<ReceiverClock>& clock = solver.clock();
  in.clear();
  for (std::size_t slot = 0; slot < channels.size(); ++slot) {
    const auto& channel = channels[slot];
    if (!channel) continue;
    if (clock) {
      in.push_back(channel->vector_input(*clock, static_cast<int>(slot)));
    } else {  // no receive time yet: nothing can be measured
      VectorChannelInput c;
      c.slot = static_cast<int>(slot);
      c.prn = channel->prn();
      in.push_back(c);
    }
  }
  epoch = VectorEpochInput{};
  epoch.sample = sample;
  epoch.command_sample = pipelined_mode_ ? sample + step_ : sample;
  epoch.fs_hz = fs_hz_;
  if (clock) epoch.receive_time = clock->time_at(sample);
  epoch.clock_corrections_s = solver.clock_corrections_s();
  epoch.last_fix_clock_corrections_s = solver.fix_clock_corrections_s();
}

// The vector loop's turn: every channel's state and latest measurements in slot order, its commands back.
void VectorLoopPort::epoch(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                           const EpochSolver& solver, const NavigationStore& navigation) {
  next_ += step_;
  if (pipelined_mode_) {
    if (pipelined_.queued) run_pipelined();  // not run yet (no block since): in turn
    apply_pipelined(channels);
    PipelinedVector& p = pipelined_;
    collect_inputs(sample, channels, solver, p.in, p.epoch);
    p.ephemerides = navigation.ephemerides();
    p.iono = navigation.klobuchar();
    p.last_fix = solver.last_fix();
    p.epoch.ephemerides = &p.ephemerides;
    p.epoch.iono = &p.iono;
    p.epoch.last_fix = p.last_fix ? &*p.last_fix : nullptr;
    p.epoch.channels = p.in;
    p.out.assign(p.in.size(), VectorChannelCommand{});
    p.queued = solver.clock().has_value();
    return;
  }
  VectorEpochInput epoch;
  collect_inputs(sample, channels, solver, in_, epoch);
  out_.assign(in_.size(), VectorChannelCommand{});
  epoch.ephemerides = &navigation.ephemerides();
  epoch.iono = &navigation.klobuchar();
  epoch.last_fix = solver.last_fix() ? &*solver.last_fix() : nullptr;
  epoch.channels = in_;
  if (solver.clock()) loop_->update(epoch, out_);
  for (std::size_t i = 0; i < in_.size(); ++i) {
    const bool ok = in_[i].synchronised;
    channels[static_cast<std::size_t>(in_[i].slot)]->set_vector_command(ok ? out_[i] : VectorChannelCommand{});
  }
}

void VectorLoopPort::run_pipelined() {
  pipelined_.queued = false;
  loop_->update(pipelined_.epoch, pipelined_.out);
  pipelined_.answered = true;
}

// A channel released since the inputs were copied gets nothing; a new one in its slot (another PRN, or the same
// PRN re-acquired: not bit-synced, so ReceiverChannel::set_vector_command drops a vector command) stays scalar.
void VectorLoopPort::apply_pipelined(std::vector<std::unique_ptr<ReceiverChannel>>& channels) {
  if (!pipelined_.answered) return;
  pipelined_.answered = false;
  for (std::size_t i = 0; i < pipelined_.in.size(); ++i) {
    const VectorChannelInput& in = pipelined_.in[i];
    auto& channel = channels[static_cast<std::size_t>(in.slot)];
    if (!channel || channel->prn() != in.prn) continue;
    channel->set_vector_command(in.synchronised ? pipelined_.out[i] : VectorChannelCommand{});
  }
}

}  // namespace ultratrack::receiver
