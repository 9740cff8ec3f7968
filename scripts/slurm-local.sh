#!/usr/bin/env bash
# A one-node Slurm on this machine (Debian's slurm-wlm + munge), for trying campaigns and for the
# integration test of `cradle tma campaign launch`:
#   scripts/slurm-local.sh start    # munge key, slurm.conf for localhost, munged, slurmctld, slurmd
#   export SLURM_CONF=/tmp/cradle-slurm/slurm.conf   # what `start` prints: sbatch/squeue use it
#   scripts/slurm-local.sh status   # sinfo
#   scripts/slurm-local.sh stop     # stops the daemons this script started (by their pid files)
# CRADLE_SLURM_DIR moves the state folder (default /tmp/cradle-slurm). Needs root (munged and
# slurmd drop to the munge / root users as Debian's services do).
set -euo pipefail

dir="${CRADLE_SLURM_DIR:-/tmp/cradle-slurm}"
conf="$dir/slurm.conf"
host="$(hostname -s)"

die() { echo "slurm-local: $*" >&2; exit 1; }

# The pid in a pid file, when that process is alive.
alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

start_munge() {
  command -v munged >/dev/null || die "munged not found (apt-get install munge slurm-wlm)"
  mkdir -p "$dir/munge" /run/munge
  # One key for this machine: Debian's, or a fresh one in the state folder.
  local key=/etc/munge/munge.key
  if [ ! -s "$key" ]; then
    key="$dir/munge/munge.key"
    [ -s "$key" ] || dd if=/dev/urandom of="$key" bs=1 count=1024 status=none
  fi
  local owner=root
  id munge >/dev/null 2>&1 && owner=munge
  chown "$owner" "$key" "$dir/munge" /run/munge
  chmod 0400 "$key"
  chmod 0700 "$dir/munge"
  if alive "$dir/munge/munged.pid"; then return; fi
  local args=(--key-file="$key" --pid-file="$dir/munge/munged.pid" --socket=/run/munge/munge.socket.2
              --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed")
  if [ "$owner" = munge ]; then
    runuser -u munge -- munged "${args[@]}" || die "munged did not start (see $dir/munge/munged.log)"
  else
    munged --force "${args[@]}" || die "munged did not start (see $dir/munge/munged.log)"
  fi
}

write_conf() {
  local cpus mem_mb
  cpus="$(nproc --all)"
  # 90 % of the memory, in MB, so slurmd's own check never drains the node.
  mem_mb="$(awk '/MemTotal/ {printf "%d", $2 / 1024 * 0.9}' /proc/meminfo)"
  mkdir -p "$dir/state" "$dir/spool" "$dir/log"
  cat >"$conf" <<EOF
# One-node Slurm written by scripts/slurm-local.sh for $host.
ClusterName=cradle
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=30
KillWait=5
Waittime=0
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
}

start() {
  command -v slurmctld >/dev/null || die "slurmctld not found (apt-get install slurm-wlm munge)"
  [ "$(id -u)" -eq 0 ] || die "needs root (the daemons run as Debian's services would)"
  start_munge
  write_conf
  export SLURM_CONF="$conf"
  alive "$dir/slurmctld.pid" || slurmctld -f "$conf" || die "slurmctld did not start (see $dir/log)"
  alive "$dir/slurmd.pid" || slurmd -f "$conf" || die "slurmd did not start (see $dir/log)"
  # Wait until the node accepts jobs.
  for _ in $(seq 60); do
    state="$(sinfo -h -N -o %t 2>/dev/null | head -n1 || true)"
    case "$state" in
      idle* | mix* | alloc*) echo "slurm-local: up ($host, $(nproc --all) CPUs); export SLURM_CONF=$conf"
                             return ;;
      down* | drain*) scontrol update nodename="$host" state=resume >/dev/null 2>&1 || true ;;
    esac
    sleep 1
  done
  die "the node did not come up (state '${state:-none}', see $dir/log)"
}

stop() {
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    if alive "$f"; then
      pid="$(cat "$f")"
      kill "$pid"
      for _ in $(seq 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
    fi
  done
  echo "slurm-local: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) SLURM_CONF="$conf" sinfo ;;
  *) die "usage: scripts/slurm-local.sh start|stop|status" ;;
esac
