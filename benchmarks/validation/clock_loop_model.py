#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A discrete model of the common clock loop (receiver/common_clock_loop.hpp), independent of the receiver's code:
the numbers its header, pipelines/receive_options.hpp and docs/validation.md (section 16) quote.

    benchmarks/validation/clock_loop_model.py scurve      # the combined phase against per-channel arctangents
    benchmarks/validation/clock_loop_model.py loops       # channel PLLs with and without the loop on a TCXO
    benchmarks/validation/clock_loop_model.py delay       # the loop closed through its command delay, noise-free

scurve: N = 8 channels whose 20 ms prompts (unit noise per arm) all carry the same phase error; the mean of the
per-channel Costas arctangents atan(Q / I) against the phase of the prompts summed after a sign decision on I, by
Monte Carlo (20 000 draws per point), at 18-25 dB-Hz.

loops: a TCXO (h0 = 9.356e-23 s, h-2 = 2e-20 / s, Brown & Hwang's random walk; white frequency noise as the
simulator's preset) common to N = 8 channels at one C/N0; each channel a third-order Costas PLL with the receiver's
loop filter (receiver/loop_filters.cpp: b3 = 2.4, a3 = 1.1, Bn per w0 = 0.7845, its proportional term a frequency
held over the next block, the NCO phase never jumped) updated every N x 20 ms at Bn = min(B, 0.2 / T); optionally
the common loop (second order, damping 0.707, its 20 ms updates on the summed prompts) whose frequency reaches the
NCOs d epochs after the epoch whose prompts it was computed from: a prompt's epoch ends up to a period before the
vector epoch that reads it and the command runs from the channel's next epoch start, up to a period after it; from
the middle of the measured epoch that is 1.5 (+-1) periods, d = 2, for the serial loop (the default) and one period
more, d = 3, for the pipelined one (pipelines/receive_options.hpp: ut_pipelined). Printed
per case over four seeds and 35 s after a 5 s start: the median channel's RMS phase error (deg, wrapped to the
Costas range) and the fraction of channels that slipped (a quarter cycle from where they started: a Costas loop's;
a PLL on known bits has half a cycle). Pure Python: about 10 s.

delay: the common loop alone and noise-free, closed through d epochs: a 1 Hz frequency step and a 5 Hz/s ramp.
"""
import cmath
import math
import random
import sys

F_L1 = 1575.42e6
H0, H_MINUS2 = 9.356e-23, 2e-20
T = 0.02


def scurve():
    rng = random.Random(2)
    n_draws, channels = 20000, 8
    print("cn0_dbhz  error_deg  mean_of_arctangents_deg  summed_prompts_deg")
    for cn0 in (18.0, 20.0, 22.0, 25.0):
        a = math.sqrt(2.0 * 10 ** (cn0 / 10.0) * T)
        for deg in (3, 30, 45, 60):
            phi = math.radians(deg)
            mean_atan = summed = 0.0
            for _ in range(n_draws):
                m = si = sq = 0.0
                for _ in range(channels):
                    i = a * math.cos(phi) + rng.gauss(0, 1)
                    q = a * math.sin(phi) + rng.gauss(0, 1)
                    m += math.atan(q / i)
                    b = 1.0 if i >= 0.0 else -1.0
                    si += b * i
                    sq += b * q
                mean_atan += m / channels
                summed += math.atan2(sq, si)
            print(f"{cn0:8.0f}  {deg:9d}  {math.degrees(mean_atan / n_draws):23.1f}  {math.degrees(summed / n_draws):18.1f}")


def run(cn0, bn_channel, epochs, bn_common, delay, seed, duration=40.0, channels=8, clock=True):
    rng = random.Random(seed)
    sub = 10
    dt = T / sub
    q_w = (2 * math.pi * F_L1) ** 2 * H0 / 2 * clock
    q_rw = (2 * math.pi * F_L1) ** 2 * 2 * math.pi**2 * H_MINUS2 * clock
    amp = math.sqrt(2 * 10 ** (cn0 / 10.0) * T)
    t_loop = epochs * T
    w0 = min(bn_channel, 0.2 / t_loop) / 0.7845
    theta = [0.0] * channels
    f_ch = [0.0] * channels
    a_ch = [0.0] * channels
    fi_ch = [0.0] * channels
    acc = [0j] * channels
    count = 0
    phi = w = 0.0
    wc = bn_common / 0.53 if bn_common > 0 else 0.0
    f_common = integrator = 0.0
    pending = [0.0] * delay  # outputs in flight: the one computed now runs from epoch k + delay + 1
    sq = [0.0] * channels
    slipped = [False] * channels
    start = None
    n = 0
    for k in range(int(duration / T)):
        sums = [0j] * channels
        for _ in range(sub):
            w += math.sqrt(q_rw * dt) * rng.gauss(0, 1)
            phi += w * dt + math.sqrt(q_w * dt) * rng.gauss(0, 1)
            for i in range(channels):
                theta[i] += (f_ch[i] + f_common) * dt
                sums[i] += cmath.exp(1j * (phi - theta[i]))
        z = [amp * s / sub + complex(rng.gauss(0, 1), rng.gauss(0, 1)) for s in sums]
        if k * T > 5.0:
            err = [phi - x for x in theta]
            if start is None:
                start = err[:]
            for i in range(channels):
                e = math.remainder(err[i], math.pi)
                sq[i] += e * e
                slipped[i] = slipped[i] or abs(err[i] - start[i]) > math.pi / 2
            n += 1
        if bn_common > 0:
            total = sum(x if x.real >= 0 else -x for x in z)
            m = math.atan2(total.imag, total.real)
            integrator += wc * wc * T * m
            out = integrator + 2 * 0.707 * wc * m
            pending.append(out)
            f_common = pending.pop(0)
        for i in range(channels):
            acc[i] += z[i]
        count += 1
        if count == epochs:
            for i in range(channels):
                e = math.atan(acc[i].imag / acc[i].real)
                # receiver/loop_filters.cpp (in rad here): rate and frequency integrators, the proportional term a
                # frequency held over the next block (the NCO's phase is never jumped)
                rate0, freq0 = a_ch[i], fi_ch[i]
                a_ch[i] += w0**3 * t_loop * e
                fi_ch[i] += t_loop * (0.5 * (a_ch[i] + rate0) + 1.1 * w0 * w0 * e)
                f_ch[i] = 0.5 * (fi_ch[i] + freq0) + 2.4 * w0 * e
                acc[i] = 0j
            count = 0
    rms = sorted(math.degrees(math.sqrt(x / n)) for x in sq)
    return rms[channels // 2], sum(slipped) / channels


def loops():
    cases = [  # (channel Bn, epochs, common Bn, d, label); d: the loop's output runs d epochs after its prompts
        (5.0, 1, 0.0, 2, "channel PLL 5 Hz / 20 ms alone (a TCXO's choice without the loop)"),
        (2.0, 5, 0.0, 2, "channel PLL 2 Hz / 100 ms alone"),
        (2.0, 5, 5.0, 1, "2 Hz / 100 ms + common loop 5 Hz, d = 1 (no delay but the epoch's own)"),
        (2.0, 5, 5.0, 2, "2 Hz / 100 ms + common loop 5 Hz, d = 2 (the serial loop)"),
        (2.0, 5, 5.0, 3, "2 Hz / 100 ms + common loop 5 Hz, d = 3 (the pipelined loop)"),
        (2.0, 5, 4.0, 3, "2 Hz / 100 ms + common loop 4 Hz, d = 3"),
        (2.0, 1, 5.0, 2, "2 Hz / 20 ms (bits unknown) + common loop 5 Hz, d = 2"),
        (2.0, 1, 5.0, 3, "2 Hz / 20 ms (bits unknown) + common loop 5 Hz, d = 3"),
        (5.0, 1, 5.0, 2, "5 Hz / 20 ms + common loop 5 Hz, d = 2"),
        (2.0, 5, 8.0, 2, "2 Hz / 100 ms + common loop 8 Hz, d = 2"),
    ]
    seeds = (3, 4, 5, 6)
    print("cn0_dbhz  case  rms_phase_deg(seeds 3-6)  slipped(seeds 3-6)")
    for cn0 in (18.0, 20.0, 22.0, 25.0):
        for bn, epochs, bc, d, label in cases:
            r = [run(cn0, bn, epochs, bc, d - 1, seed) for seed in seeds]
            print(f"{cn0:8.0f}  {label}: " + " ".join(f"{x[0]:.1f}" for x in r) + " deg, slipped " +
                  " ".join(f"{x[1]:.2f}" for x in r), flush=True)


def delay():
    """The common loop alone, noise-free, closed through d epochs (its output from epoch n's mean phase runs from
    epoch n + d on): the NCO frequency's overshoot after a 1 Hz step of the signal, its largest error 1-2 s after
    the step, and the phase error a 5 Hz/s ramp leaves (tests/receiver/common_clock_loop_test.cpp)."""
    def closed(d, step_hz, ramp_hzps, bn=5.0):
        w0 = bn / 0.53
        integrator = 0.0  # rad/s
        in_flight = [0.0] * d  # rad/s; in_flight[0] runs in this epoch
        signal = replica = 0.0
        overshoot, late, error = 0.0, 0.0, 0.0
        for k in range(500):
            f_signal = 2 * math.pi * (step_hz + ramp_hzps * k * T)
            f_nco = in_flight[0]
            error = signal - replica + 0.5 * T * (f_signal - f_nco)
            signal += f_signal * T
            replica += f_nco * T
            e_hz = (f_nco - f_signal) / (2 * math.pi)
            overshoot = max(overshoot, e_hz)
            if 50 <= k < 100:
                late = max(late, abs(e_hz))
            m = error
            integrator += w0 * w0 * T * m
            out = integrator + 2 * 0.707 * w0 * m
            in_flight = in_flight[1:] + [out]
        return overshoot, late, error
    print("d  step_overshoot_hz  error_1_to_2_s_hz  ramp_phase_error_rad")
    for d in (1, 2, 3):
        o, c, _ = closed(d, 1.0, 0.0)
        _, _, r = closed(d, 0.0, 5.0)
        print(f"{d}  {o:17.3f}  {c:17.4f}  {r:20.3f}")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "scurve":
        scurve()
    elif what == "loops":
        loops()
    elif what == "delay":
        delay()
    else:
        sys.exit(__doc__)
