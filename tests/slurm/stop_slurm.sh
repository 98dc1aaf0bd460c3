#!/usr/bin/env bash
# Stops the private Slurm cluster that tests/slurm/start_slurm.sh started in DIR: cancels its jobs,
# stops slurmd, slurmctld and munged, and ends job steps still running from its spool folder.
# Safe to run more than once, and on a folder where nothing (or only part) was started.
#
# Usage: tests/slurm/stop_slurm.sh DIR
set -uo pipefail

if [[ $# -ne 1 || -z "$1" ]]; then
  echo "usage: $0 DIR" >&2
  exit 3
fi
[[ -d "$1" ]] || exit 0
dir=$(cd "$1" && pwd)

# True when PID is alive and its command is DAEMON (guards against a pid reused by another process).
is_daemon() {
  local pid=$1 daemon=$2 exe
  [[ "$pid" =~ ^[0-9]+$ ]] || return 1
  kill -0 "$pid" 2>/dev/null || return 1
  exe=$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | awk '{ print $1 }')
  [[ "$(basename "${exe:-none}")" == "$daemon" ]]
}

# Sends TERM to every PID given, waits up to 10 s for all of them, then KILLs the survivors.
stop_pids() {
  local pid alive
  [[ $# -gt 0 ]] || return 0
  kill -TERM "$@" 2>/dev/null
  for _ in $(seq 1 100); do
    alive=0
    for pid in "$@"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [[ $alive -eq 0 ]] && return 0
    sleep 0.1
  done
  kill -KILL "$@" 2>/dev/null
  return 0
}

# Cancel this cluster's jobs while its controller still answers, so no job step outlives it.
if [[ -f "$dir/slurm.conf" && -f "$dir/slurmctld.pid" ]] &&
   is_daemon "$(cat "$dir/slurmctld.pid")" slurmctld; then
  export SLURM_CONF="$dir/slurm.conf"
  jobs=$(timeout 10 squeue -h -o %A 2>/dev/null | sort -u)
  if [[ -n "$jobs" ]]; then
    # shellcheck disable=SC2086
    timeout 10 scancel $jobs 2>/dev/null
    for _ in $(seq 1 100); do
      [[ -z "$(timeout 10 squeue -h -o %A 2>/dev/null)" ]] && break
      sleep 0.1
    done
  fi
fi

# The three daemons stop together (each takes about 2 s to shut down).
pids=()
for daemon in slurmd slurmctld munged; do
  pidfile="$dir/$daemon.pid"
  [[ -f "$pidfile" ]] || continue
  pid=$(cat "$pidfile")
  is_daemon "$pid" "$daemon" && pids+=("$pid")
done
stop_pids "${pids[@]}"
rm -f "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munged.pid"

# Job steps (slurmstepd and the processes of the job) hold files in the spool folder; any still
# alive belongs to this cluster only.
if [[ -d "$dir/spool" ]]; then
  for fd_dir in /proc/[0-9]*/fd; do
    pid=${fd_dir#/proc/}
    pid=${pid%/fd}
    [[ "$pid" == "$$" ]] && continue
    if ls -l "$fd_dir" 2>/dev/null | grep -q -- "-> $dir/spool/"; then
      kill -KILL "$pid" 2>/dev/null || true
    fi
  done
fi
exit 0
