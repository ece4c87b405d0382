#!/usr/bin/env bash
# A real one-node Slurm cluster in a folder of its own, for the `cluster` tests (and for trying
# `swish bake --slurm` by hand). Debian 12's slurm-wlm 22.05 and munge, run as root, no systemd, no
# cgroups: munged with its own key and socket, slurmctld and slurmd on ports of their own, all state,
# logs and pid files under DIR. Nothing outside DIR is touched.
#
#   local_slurm.sh start DIR [WATCH_PID]   start the daemons; prints `export SLURM_CONF=DIR/slurm.conf`.
#                                          With WATCH_PID, a watchdog stops them when that process ends
#                                          (a test killed by its timeout leaves nothing running).
#   local_slurm.sh stop DIR                stop what `start` started, by the pids in DIR/*.pid
#
# Exit status of start: 0 running (the node is idle and takes jobs), 3 Slurm or munge is not installed,
# 1 the daemons did not come up (their logs are printed).
set -euo pipefail

cmd=${1:-}
dir=${2:-}
if [ -z "$cmd" ] || [ -z "$dir" ]; then
  echo "usage: $0 start|stop DIR [WATCH_PID]" >&2
  exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

# Stops one daemon by the pid in its file, TERM then KILL; removes the file.
stop_pid_file() {
  local f=$1 pid
  [ -f "$f" ] || return 0
  pid=$(cat "$f" 2>/dev/null || true)
  rm -f "$f"
  [[ "$pid" =~ ^[0-9]+$ ]] || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for _ in $(seq 50); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "$pid" 2>/dev/null || true
}

# The job steps still on the node: slurmstepd keeps a socket <host>_<job>.<step> in the spool folder.
steps_left() {
  local f
  for f in "$dir"/spool/*; do [ -S "$f" ] && return 0; done
  return 1
}

stop_all() {
  # The watchdog first, so that it does not race this stop.
  stop_pid_file "$dir/watchdog.pid"
  # Jobs still queued or running are cancelled while the controller is up, and their steps (slurmstepd
  # and the job's processes, which slurmd's shutdown would leave running) given 15 s to end.
  if [ -f "$dir/slurmctld.pid" ] && [ -f "$dir/slurm.conf" ]; then
    SLURM_CONF="$dir/slurm.conf" PATH="$PATH:/usr/sbin" scancel --user="$(id -un)" 2>/dev/null || true
    for _ in $(seq 75); do
      steps_left || break
      sleep 0.2
    done
    if steps_left; then
      echo "local_slurm: job steps still running after scancel: $(find "$dir/spool" -maxdepth 1 -type s -printf '%f ')" >&2
    fi
  fi
  # Then the node, the controller, munge.
  stop_pid_file "$dir/slurmd.pid"
  stop_pid_file "$dir/slurmctld.pid"
  stop_pid_file "$dir/munged.pid"
}

if [ "$cmd" = stop ]; then
  stop_all
  exit 0
fi
[ "$cmd" = start ] || { echo "$0: unknown command '$cmd' (start|stop)" >&2; exit 2; }
if [ -f "$dir/slurmctld.pid" ] || [ -f "$dir/munged.pid" ]; then
  echo "local_slurm: $dir already has a cluster started (stop it first: $0 stop $dir)" >&2
  exit 1
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "local_slurm: the local cluster runs its daemons as root (SlurmUser=root); this is uid $(id -u)" >&2
  exit 3
fi

for exe in munged slurmctld slurmd sbatch squeue scontrol; do
  if ! PATH="$PATH:/usr/sbin:/sbin" command -v "$exe" >/dev/null; then
    echo "local_slurm: '$exe' is not installed (Debian: apt-get install slurm-wlm slurm-client munge)" >&2
    exit 3
  fi
done
export PATH="$PATH:/usr/sbin:/sbin"

# Two free TCP ports on this machine for the controller and the node.
free_port() {
  local p
  for _ in $(seq 200); do
    p=$(( 20000 + RANDOM % 30000 ))
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then echo "$p"; return 0; fi
  done
  echo "local_slurm: no free port found" >&2
  return 1
}
ctld_port=$(free_port)
slurmd_port=$(free_port)
while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(free_port); done

host=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chmod 700 "$dir/munge"

# munge: a key of its own (1 KiB of random bytes), its own socket, pid and seed files.
head -c 1024 /dev/urandom > "$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munged.pid" --seed-file="$dir/munge/munged.seed" --log-file="$dir/munged.log"

cat > "$dir/slurm.conf" <<CONF
# Written by tests/cluster/local_slurm.sh: one node, localhost only, no cgroups.
ClusterName=swishlocal
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
# Scheduling passes every few seconds (defaults 60 s and 30 s): a job whose dependency is met starts at once.
SchedulerParameters=sched_interval=2,bf_interval=2
MpiDefault=none
ReturnToService=2
JobRequeue=1
MinJobAge=600
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

export SLURM_CONF="$dir/slurm.conf"
slurmctld -f "$dir/slurm.conf"
slurmd -f "$dir/slurm.conf"

if [ -n "${3:-}" ]; then
  watch=$3
  # Stops the daemons when the process that asked for them ends without calling stop.
  nohup bash -c "while kill -0 $watch 2>/dev/null; do sleep 1; done; exec bash '$0' stop '$dir'" \
    >/dev/null 2>&1 &
  echo $! > "$dir/watchdog.pid"
fi

# Ready when the node is idle (slurmd registered with the controller).
for _ in $(seq 150); do
  state=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
  if [ "$state" = idle ]; then
    echo "export SLURM_CONF=$dir/slurm.conf"
    exit 0
  fi
  sleep 0.2
done
echo "local_slurm: the node did not come up (state '${state:-none}'); logs:" >&2
for f in munged.log slurmctld.log slurmd.log; do
  echo "--- $dir/$f" >&2
  tail -n 20 "$dir/$f" >&2 2>/dev/null || true
done
stop_all
exit 1
