#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How well can any receiver measure a snapshot's code phase? The Cramer-Rao bound of the C/A code delay through an
ideal front end of two-sided bandwidth B (rectangular, centred on the carrier), beside our snapshot's non-coherent
early-late discriminator (receiver/snapshot_measurement.hpp: sigma^2 = d / (4 C/N0 T) (1 + 2 / ((2 - d) C/N0 T_coh)),
d = 0.5 chip, T_coh = 5 ms below 40 ms of signal, else 10 ms), and what a 3-D error within 10 m in 95 % of fixes
asks of the per-satellite error.

  CRB:  var(tau) = 1 / (8 pi^2 beta^2 T C/N0),  beta^2 = int f^2 S(f) df / int S(f) df over |f| <= B / 2,
        S(f) = Tc sinc^2(f Tc) (the C/A code's spectrum; Kaplan & Hegarty, 3rd ed., ch. 8).
  3-D:  the error's 95 % point is about 1.6 PDOP sigma (chi with 3 degrees of freedom: 2.80 x the per-axis sigma,
        PDOP sigma / sqrt(3) per axis), so 10 m asks for sigma <= 10 / (1.6 PDOP).

    benchmarks/validation/snapshot_code_bound.py [--bandwidth-mhz 2.046] [--pdop 1.5]
"""
import argparse
import math

C = 299_792_458.0
CHIP_S = 1.0 / 1.023e6


def rms_bandwidth_hz(bandwidth_hz, steps=200_000):
    """beta for the C/A spectrum through |f| <= bandwidth / 2 (midpoint rule)."""
    half = 0.5 * bandwidth_hz
    df = 2.0 * half / steps
    num = den = 0.0
    for k in range(steps):
        f = -half + (k + 0.5) * df
        x = math.pi * f * CHIP_S
        s = CHIP_S * (math.sin(x) / x) ** 2 if x != 0.0 else CHIP_S
        num += f * f * s * df
        den += s * df
    return math.sqrt(num / den)


def crb_sigma_m(cn0_dbhz, t_s, beta_hz):
    cn0 = 10.0 ** (cn0_dbhz / 10.0)
    return C * math.sqrt(1.0 / (8.0 * math.pi ** 2 * beta_hz ** 2 * t_s * cn0))


def discriminator_sigma_m(cn0_dbhz, t_s, d=0.5):
    cn0 = 10.0 ** (cn0_dbhz / 10.0)
    t_coh = 0.005 if t_s < 0.040 else 0.010
    var = d / (4.0 * cn0 * t_s) * (1.0 + 2.0 / ((2.0 - d) * cn0 * t_coh))
    return math.sqrt(var) * CHIP_S * C


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bandwidth-mhz", type=float, default=2.046, help="two-sided front-end bandwidth (2.046: the main lobe)")
    ap.add_argument("--pdop", type=float, default=1.5)
    a = ap.parse_args()
    beta = rms_bandwidth_hz(a.bandwidth_mhz * 1e6)
    need = 10.0 / (1.6 * a.pdop)
    print(f"front end {a.bandwidth_mhz:.3f} MHz two-sided: RMS bandwidth {beta / 1e3:.1f} kHz; 10 m in 95 % at PDOP "
          f"{a.pdop} asks for <= {need:.1f} m per satellite")
    print("| C/N0 | snapshot | CRB per satellite | our discriminator (d = 0.5) | CRB 3-D 95 % at that PDOP |")
    print("|---|---|---|---|---|")
    for cn0 in (45.0, 35.0):
        for ms in (20, 100):
            crb = crb_sigma_m(cn0, ms / 1000.0, beta)
            print(f"| {cn0:.0f} dB-Hz | {ms} ms | {crb:.1f} m | {discriminator_sigma_m(cn0, ms / 1000.0):.1f} m | "
                  f"{1.6 * a.pdop * crb:.1f} m |")
    # The bandwidth at which the bound meets the need at 35 dB-Hz over 20 ms.
    b = a.bandwidth_mhz * 1e6
    while crb_sigma_m(35.0, 0.020, rms_bandwidth_hz(b, 20_000)) > need and b < 200e6:
        b *= 1.1
    print(f"35 dB-Hz over 20 ms meets {need:.1f} m per satellite only with a front end of about {b / 1e6:.0f} MHz "
          f"(two-sided) and an estimator at the bound")


if __name__ == "__main__":
    main()
