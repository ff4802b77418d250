# SPDX-License-Identifier: GPL-3.0-or-later
# Sourced by the benchmark scripts (after setting $root, the checkout): the broadcast ephemeris their scenarios use,
# and how to move them to another file.
#
# Default: the shipped tests/data/brdc3540_0000-0200.14n (IGS, 2014-12-20: GPS week 1823, valid from TOW 511200 to
# 532800; tests/data/README.md). The committed scenarios start inside it (tow 530396-530776, 10 satellites above
# 5 deg at Nagoya). Another file: `--brdc FILE --week W --tow-shift S` puts every scenario on week W and S seconds
# later. Keep S a multiple of 750 s (the 25-page cycle of subframes 4 and 5) so that each run starts at the same
# point of the navigation message. The figures marked [E] in docs/validation.md were measured on brdc0010.22n
# (2022-01-01, not shipped: ../shared/data on the machine they were measured on), i.e. with
#   --brdc ../shared/data/brdc0010.22n --week 2190 --tow-shift -12000
# ULTRATRACK_BRDC in the environment sets the default file.
brdc=${ULTRATRACK_BRDC:-$root/tests/data/brdc3540_0000-0200.14n}
brdc_week=""      # empty: each scenario's own gps_week
brdc_tow_shift=0  # seconds added to each scenario's tow_s

# The week and start of a scenario written by a script: its values on the shipped file, moved as asked.
brdc_week_or() { echo "${brdc_week:-$1}"; }
brdc_tow_plus() { awk -v t="$1" -v s="$brdc_tow_shift" 'BEGIN { printf "%.1f", t + s }'; }

# A scenario file with its `rinex`, `gps_week` and `tow_s` lines set for the chosen ephemeris (stdout).
retime_scenario() {  # scenario_file
  awk -v nav="$brdc" -v week="$brdc_week" -v shift="$brdc_tow_shift" '
    /^rinex = / { $0 = "rinex = \"" nav "\"" }  # the whole line, as the scripts always wrote it
    /^gps_week = [0-9]/ && week != "" { sub(/^gps_week = [0-9]+/, "gps_week = " week) }
    /^tow_s = [0-9]/ && shift != 0 {
      match($0, /^tow_s = [0-9.]+/)
      $0 = sprintf("tow_s = %.1f", substr($0, 9, RLENGTH - 8) + shift) substr($0, RLENGTH + 1)
    }
    { print }' "$1"
}
