#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the two land routes of the odometer benchmark (seed 004) as ins/trajectory.hpp segment files:
scenarios/odometer_loop_segments.csv     a ~12.5 km ordinary-road loop (turns at intersections, roundabouts,
                                         lane changes, long gentle curves of 0.5-2.5 deg/s, slopes, stops)
scenarios/odometer_motorway_segments.csv a ~110 km mostly-motorway drive (curves of 0.2-1.2 deg/s, lane changes,
                                         interchanges, slopes, a toll stop, town roads at both ends)
Deterministic (no randomness): run it again to reproduce the committed files exactly.
Usage: python3 benchmarks/odometer_routes.py [scenarios_dir]"""
import math
import sys
from pathlib import Path


class Route:
    def __init__(self):
        self.rows = []  # duration_s, accel_mps2, turn_rate_dps, climb_rate_mps, grade_deg
        self.v = 0.0
        self.grade = 0.0
        self.heading = 0.0
        self.distance = 0.0

    def seg(self, dur, accel=0.0, turn=0.0):
        self.rows.append((dur, accel, turn, 0.0, self.grade))
        self.distance += self.v * dur + 0.5 * accel * dur * dur
        self.v += accel * dur
        self.heading += turn * dur

    def straight(self, metres):
        self.seg(round(metres / self.v, 1))

    def speed(self, v_new, accel=1.2):
        if abs(v_new - self.v) < 1e-9:
            return
        dur = abs(v_new - self.v) / accel
        self.seg(round(dur, 2), math.copysign(accel, v_new - self.v))

    def stop(self, seconds, decel=1.5):
        self.speed(0.0, decel)
        self.v = 0.0
        self.seg(seconds)

    def turn(self, degrees, rate_dps):
        self.seg(round(abs(degrees) / rate_dps, 2), turn=math.copysign(rate_dps, degrees))

    def lane_change(self, side, rate_dps=3.0, half_s=2.0):
        self.seg(half_s, turn=side * rate_dps)
        self.seg(half_s, turn=-side * rate_dps)

    def slope(self, grade_deg):
        self.grade = grade_deg

    def roundabout(self, exit_deg):
        """Right-hand traffic: enter right 30 deg, round to the left, leave right 30 deg: net exit_deg (left +)."""
        self.speed(7.0, 1.5)
        self.turn(30.0, 12.0)
        self.turn(-(60.0 + exit_deg), 25.0)  # the ring, counterclockwise
        self.turn(30.0, 12.0)

    def write(self, path, comment):
        with open(path, "w") as f:
            for line in comment.strip().splitlines():
                f.write("# " + line + "\n")
            f.write("duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n")
            for d, a, t, c, g in self.rows:
                f.write(f"{d:g},{a:g},{t:g},{c:g},{g:g}\n")


def loop():
    r = Route()
    r.seg(120.0)  # parked: the static alignment (gyrocompassing)
    r.speed(14.0)  # 50 km/h town road
    r.straight(450)  # the GNSS alignment and calibration leg
    for side in range(4):
        sign = 1.0 if side % 2 else -1.0
        r.lane_change(+1)
        r.straight(150)
        r.turn(15.0 * sign, 1.25)  # long gentle curves: inside the thresholds' range
        r.straight(150)
        r.slope(2.5 if side % 2 == 0 else -2.5)
        r.turn(-15.0 * sign, 1.75)
        r.straight(200)
        r.slope(0.0)
        r.lane_change(-1)
        r.straight(100)
        r.stop(20.0)  # traffic light
        r.speed(12.0)
        r.turn(-90.0, 9.0)  # right at an intersection
        r.straight(250)
        r.turn(12.0 * sign, 0.9)
        r.turn(-12.0 * sign, 0.9)
        r.straight(150)
        r.roundabout(0.0)  # straight through
        r.speed(15.0)
        r.straight(200)
        r.turn(30.0, 2.25)
        r.straight(100)
        r.turn(-30.0, 2.25)
        r.straight(150)
        r.speed(14.0)
    r.straight(200)
    r.stop(10.0)
    return r


def motorway():
    r = Route()
    r.seg(120.0)  # parked: the static alignment (gyrocompassing)
    r.speed(14.0)
    r.straight(1500)  # town: alignment and calibration with GNSS
    r.turn(-90.0, 8.0)
    r.straight(400)
    r.roundabout(90.0)
    r.straight(300)
    # on-ramp: a long right-hand curve while accelerating
    r.turn(-120.0, 6.0)
    r.speed(28.0, 1.0)
    laps = 0
    while r.distance < 104000.0:
        k = laps % 4
        r.straight(3000 + 700 * k)
        r.lane_change(+1, 1.5, 3.0)
        r.slope([2.0, -1.5, 3.0, -2.5][k])
        r.turn([18.0, -12.0, 25.0, -20.0][k], [0.4, 0.25, 0.6, 0.35][k])
        r.straight(1500)
        r.slope(0.0)
        r.lane_change(-1, 1.5, 3.0)
        r.turn([-30.0, 22.0, -15.0, 35.0][k], [0.8, 1.2, 0.3, 1.0][k])
        r.straight(2500)
        if k == 1:  # an interchange: off-ramp loop onto another motorway
            r.speed(18.0, 1.0)
            r.turn(-40.0, 4.0)
            r.turn(250.0, 7.0)
            r.speed(28.0, 1.0)
        if k == 3 and laps == 7:  # a toll gate
            r.stop(30.0, 1.5)
            r.speed(28.0, 1.2)
        laps += 1
    r.speed(14.0, 1.0)
    r.turn(-90.0, 5.0)
    r.straight(600)
    r.roundabout(-90.0)
    r.straight(500)
    r.stop(10.0)
    return r


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "scenarios")
    lo = loop()
    lo.write(out / "odometer_loop_segments.csv",
             f"""An ordinary-road loop of {lo.distance / 1000:.1f} km for the odometer benchmark (seed 004 Table 1): town roads at
30-54 km/h, intersections (9-10 deg/s), roundabouts, lane changes, gentle curves of 0.9-2.25 deg/s, +-2.5 deg
slopes, traffic-light stops. Written by benchmarks/odometer_routes.py; columns as ins/trajectory.hpp.""")
    mw = motorway()
    mw.write(out / "odometer_motorway_segments.csv",
             f"""A {mw.distance / 1000:.1f} km mostly-motorway drive for the odometer benchmark (seed 004 Table 2): town roads and a
roundabout at both ends, 100 km/h motorway with curves of 0.25-1.2 deg/s, lane changes, +-3 deg slopes, an
interchange loop, a toll stop. Written by benchmarks/odometer_routes.py; columns as ins/trajectory.hpp.""")
    print(f"loop {lo.distance:.0f} m {sum(x[0] for x in lo.rows):.0f} s; motorway {mw.distance:.0f} m "
          f"{sum(x[0] for x in mw.rows):.0f} s")


if __name__ == "__main__":
    main()
