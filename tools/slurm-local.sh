#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A single-node Slurm on this machine, for `ultratrack campaign run --engine slurm` and its test:
#   tools/slurm-local.sh start    write the configuration, start munged, slurmctld and slurmd, wait for the node
#   tools/slurm-local.sh status   the daemons' process ids, `sinfo` and `squeue`; exit 1 when not running
#   tools/slurm-local.sh stop     stop the three daemons (state and logs stay)
#   tools/slurm-local.sh env      the line to eval so that sbatch, squeue and scontrol find this cluster
# Debian's slurm-wlm and munge (apt-get install munge slurmctld slurmd slurm-client), daemons started by this
# script (no systemd). Made for containers without cgroups: ProctrackType=proctrack/linuxproc, TaskPlugin=task/none,
# no accounting. Everything (slurm.conf, munge key and socket, state, spool, logs, pid files) lives under
# ULTRATRACK_SLURM_DIR (default ${XDG_RUNTIME_DIR:-/tmp}/ultratrack-slurm); the clients find it through SLURM_CONF.
# Ports: ULTRATRACK_SLURM_PORT (slurmctld, default 6817) and the next one (slurmd).
set -euo pipefail

dir=${ULTRATRACK_SLURM_DIR:-${XDG_RUNTIME_DIR:-/tmp}/ultratrack-slurm}
port=${ULTRATRACK_SLURM_PORT:-6817}
conf=$dir/slurm.conf
node=$(hostname -s)

die() { echo "slurm-local.sh: $*" >&2; exit 1; }

# The pid in a pid file, when that process is alive.
alive() { [[ -f $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

write_config() {
  local user cpus mem_mb
  user=$(id -un)
  cpus=$(nproc)
  mem_mb=$(awk '/^MemTotal:/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
  cat > "$conf" <<EOF
# Written by tools/slurm-local.sh: one node, daemons as $user, no cgroups (containers), no accounting.
ClusterName=ultratrack-local
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldTimeout=30
SlurmdTimeout=30
MaxArraySize=100001
MaxJobCount=200000
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
  for program in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
    command -v "$program" >/dev/null || [[ -x /usr/sbin/$program ]] ||
      die "$program not found: apt-get install munge slurmctld slurmd slurm-client"
  done
  export PATH=$PATH:/usr/sbin
  if alive "$dir/slurmctld.pid" && alive "$dir/slurmd.pid"; then
    echo "slurm-local.sh: already running ($dir)"
    return 0
  fi
  mkdir -p "$dir"/{munge,state,spool,log}
  chmod 700 "$dir" "$dir/munge"
  if [[ ! -f $dir/munge/munge.key ]]; then
    (umask 077 && head -c 1024 /dev/urandom > "$dir/munge/munge.key")
  fi
  chmod 400 "$dir/munge/munge.key"
  write_config
  if ! alive "$dir/munge/munged.pid"; then
    munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
      --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" ||
      die "munged did not start (see $dir/log/munged.log)"
  fi
  alive "$dir/slurmctld.pid" || slurmctld -f "$conf" || die "slurmctld did not start (see $dir/log/slurmctld.log)"
  alive "$dir/slurmd.pid" || slurmd -f "$conf" -N "$node" || die "slurmd did not start (see $dir/log/slurmd.log)"
  # Ready when the node accepts work (idle or mixed); a node left down by a past run is resumed.
  for _ in $(seq 1 60); do
    state=$(SLURM_CONF=$conf sinfo -h -N -o '%T' 2>/dev/null | head -1 || true)
    case $state in
      idle* | mixed* | allocated*) echo "slurm-local.sh: running, node $node $state ($dir)"; env_line; return 0 ;;
      down* | drain*) SLURM_CONF=$conf scontrol update nodename="$node" state=resume 2>/dev/null || true ;;
    esac
    sleep 1
  done
  die "the node did not become idle within 60 s (state '${state:-none}'; see $dir/log/)"
}

stop() {
  # slurmd first (it may hold job steps), then the controller, then munge.
  for pid_file in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    alive "$pid_file" || continue
    pid=$(cat "$pid_file")
    kill "$pid"
    for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
    rm -f "$pid_file"
  done
  echo "slurm-local.sh: stopped ($dir)"
}

status() {
  local running=0
  for pid_file in "$dir/munge/munged.pid" "$dir/slurmctld.pid" "$dir/slurmd.pid"; do
    name=$(basename "$pid_file" .pid)
    if alive "$pid_file"; then echo "$name: running (pid $(cat "$pid_file"))"; else echo "$name: not running"; running=1; fi
  done
  ((running == 0)) || return 1
  SLURM_CONF=$conf sinfo
  SLURM_CONF=$conf squeue
}

env_line() { echo "export SLURM_CONF=$conf"; }

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) status ;;
  env) env_line ;;
  *) echo "usage: tools/slurm-local.sh start|stop|status|env" >&2; exit 2 ;;
esac
