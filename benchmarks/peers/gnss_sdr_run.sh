#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs GNSS-SDR (Debian package gnss-sdr) on an IF file with settings equivalent to ultratrack's defaults,
# and prints its realtime factor, peak memory and last position. Used by the synthesiser cross-check and
# by the throughput comparison. Skips (exit 0, message) when gnss-sdr is not installed.
#
#   benchmarks/peers/gnss_sdr_run.sh FILE FORMAT FS_HZ OUT_DIR [CHANNELS] [IF_HZ]
#   FORMAT: i8 | i16 | f32 (interleaved I/Q) | i2 (2-bit packed I/Q as ultratrack writes it by default:
#           twos, lsb-first = GNSS-SDR's Two_Bit_Packed_File_Signal_Source, sample_type=iq, big_endian_bytes=false)
#
# GNSS-SDR configuration used (documented so that the comparison is fair): File_Signal_Source, a pass-through
# signal conditioner (no filtering or resampling), PCPS acquisition (+-5 kHz, 250 Hz step, pfa 0.01 threshold),
# DLL/PLL tracking with PLL 25 Hz / DLL 2 Hz, 0.5 chip early-late spacing, Hybrid observables, RTKLIB PVT in
# single-point mode at 10 Hz, ionosphere broadcast, troposphere Saastamoinen.
set -euo pipefail
if ! command -v gnss-sdr >/dev/null; then
  echo "gnss_sdr_run.sh: gnss-sdr is not installed (apt-get install gnss-sdr): skipped"
  exit 0
fi
file=$(realpath "$1"); format=$2; fs=$(printf "%.0f" "$3"); out=$4; channels=${5:-8}; if_hz=${6:-0}  # GNSS-SDR wants integer rates
mkdir -p "$out"
out=$(realpath "$out")
case "$format" in
  i8) item=ibyte; adapter=Ibyte_To_Complex ;;
  i16) item=ishort; adapter=Ishort_To_Complex ;;
  f32) item=gr_complex; adapter=Pass_Through ;;
  i2) item=byte; adapter=Pass_Through ;;
  *) echo "gnss_sdr_run.sh: format $format not supported" >&2; exit 2 ;;
esac
source=File_Signal_Source
[[ "$format" == i2 ]] && source=Two_Bit_Packed_File_Signal_Source
conf=$out/gnss-sdr.conf
cat > "$conf" <<CONF
[GNSS-SDR]
GNSS-SDR.internal_fs_sps=$fs
SignalSource.implementation=$source
SignalSource.filename=$file
SignalSource.item_type=$item
SignalSource.sample_type=iq
SignalSource.big_endian_bytes=false
SignalSource.sampling_frequency=$fs
SignalSource.samples=0
SignalSource.repeat=false
SignalSource.enable_throttle_control=false
SignalConditioner.implementation=Signal_Conditioner
DataTypeAdapter.implementation=$adapter
InputFilter.implementation=Pass_Through
InputFilter.item_type=gr_complex
Resampler.implementation=Pass_Through
Resampler.item_type=gr_complex
Channel.signal=1C
Channels.in_acquisition=1
Channels_1C.count=$channels
Acquisition_1C.implementation=GPS_L1_CA_PCPS_Acquisition
Acquisition_1C.item_type=gr_complex
Acquisition_1C.pfa=0.01
Acquisition_1C.doppler_max=5000
Acquisition_1C.doppler_step=250
Acquisition_1C.coherent_integration_time_ms=1
Tracking_1C.implementation=GPS_L1_CA_DLL_PLL_Tracking
Tracking_1C.item_type=gr_complex
Tracking_1C.pll_bw_hz=25.0
Tracking_1C.dll_bw_hz=2.0
Tracking_1C.early_late_space_chips=0.5
TelemetryDecoder_1C.implementation=GPS_L1_CA_Telemetry_Decoder
Observables.implementation=Hybrid_Observables
PVT.implementation=RTKLIB_PVT
PVT.positioning_mode=Single
PVT.output_rate_ms=100
PVT.display_rate_ms=1000
PVT.iono_model=Broadcast
PVT.trop_model=Saastamoinen
PVT.output_path=$out
PVT.rinexobs_rate_ms=100
PVT.flag_rtcm_server=false
PVT.enable_monitor=false
CONF
[[ "$if_hz" != 0 ]] && { echo "gnss_sdr_run.sh: non-zero IF not supported by this script" >&2; exit 2; }
log=$out/gnss-sdr.log
cd "$out"
/usr/bin/time -v -o "$out/time.txt" gnss-sdr --config_file="$conf" --log_dir="$out" >"$log" 2>&1 || true
wall=$(grep "Elapsed (wall clock)" "$out/time.txt" | awk '{print $NF}')
peak_kb=$(grep "Maximum resident set size" "$out/time.txt" | awk '{print $NF}')
bytes=$(stat -c %s "$file")
case "$format" in i8) bps=2 ;; i16) bps=4 ;; f32) bps=8 ;; i2) bps=0.5 ;; esac
python3 - "$wall" "$peak_kb" "$bytes" "$bps" "$fs" "$log" <<'PY'
import re, sys
wall, peak_kb, nbytes, bps, fs, log = sys.argv[1:]
parts = [float(p) for p in wall.split(':')]
secs = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
duration = int(nbytes) / float(bps) / float(fs)
pos = [l for l in open(log, errors='replace') if 'Position at' in l]
print(f"gnss-sdr: signal {duration:.1f} s, wall {secs:.1f} s, realtime factor {duration / secs:.2f}, "
      f"peak memory {int(peak_kb) / 1024:.0f} MB, fixes {len(pos)}")
if pos:
    print("gnss-sdr last fix:", re.sub(r"\x1b\[[0-9;]*m", "", pos[-1]).strip())
PY
