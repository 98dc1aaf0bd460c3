#!/usr/bin/env bash
# Starts a private single-node Slurm cluster (munged, slurmctld, slurmd) for this machine, with
# every file it writes inside DIR. Runs as root on a machine without systemd (a container).
#
# Usage: tests/slurm/start_slurm.sh DIR
#   DIR            folder for the cluster's key, configuration, state, spool, logs and pid files;
#                  created if missing. Stop the cluster with tests/slurm/stop_slurm.sh DIR.
# On success prints the lines of DIR/env.sh (`export SLURM_CONF=DIR/slurm.conf`); source that file
# (or set SLURM_CONF) before running sbatch, squeue, sinfo or scontrol against this cluster.
# On failure stops whatever it started, prints the tails of the daemon logs and exits 1.
# Needs: bash ci/install-deps.sh slurm (Debian slurm-wlm and munge).
#
# The configuration avoids everything a container may lack: process tracking by the process tree
# (proctrack/linuxproc) instead of cgroups, no task affinity plugin (task/none), no accounting
# database, no cgroup.conf. Ports are chosen among those nobody listens on.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if [[ $# -ne 1 || -z "$1" ]]; then
  echo "usage: $0 DIR" >&2
  exit 3
fi
mkdir -p "$1"
dir=$(cd "$1" && pwd)
chmod 755 "$dir"
# munged and slurmd put Unix sockets in DIR; a socket path may not exceed 107 bytes.
if [[ ${#dir} -gt 60 ]]; then
  echo "start_slurm: '$dir' is too long (${#dir} characters) for the Unix sockets inside it; use a folder" \
       "of at most 60 characters, e.g. under /tmp" >&2
  exit 3
fi
t0=$(date +%s.%N)
note() { printf 'start_slurm: %5.1f s  %s\n' "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')" "$*" >&2; }

ready=0
# Any failure (a `fail` or an unexpected command error): the daemon log tails, then everything
# started so far is stopped.
on_exit() {
  local code=$?
  [[ $ready -eq 1 ]] && return
  [[ $code -eq 0 ]] && code=1
  echo "start_slurm: failed (exit $code); logs in $dir/log" >&2
  for log in "$dir/log/munged.out" "$dir/log/slurmctld.log" "$dir/log/slurmd.log" \
             "$dir/log/slurmctld.out" "$dir/log/slurmd.out"; do
    if [[ -s "$log" ]]; then
      echo "---- last lines of $log" >&2
      tail -n 25 "$log" >&2
    fi
  done
  bash "$here/stop_slurm.sh" "$dir" >&2 || true
  exit "$code"
}
trap on_exit EXIT

fail() {
  echo "start_slurm: $*" >&2
  exit 1
}

for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$tool" >/dev/null 2>&1 ||
    fail "'$tool' is not installed; run: bash ci/install-deps.sh slurm"
done
if [[ $(id -u) -ne 0 ]]; then
  fail "must run as root (the daemons run as root with SlurmUser=root)"
fi

# A previous cluster in the same folder is stopped first, so starting again is safe.
bash "$here/stop_slurm.sh" "$dir" >/dev/null 2>&1 || true
rm -rf "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
chmod 755 "$dir/munge"

# ---- munge: a fresh key and a daemon on a private socket
mungekey --create --keyfile="$dir/munge/munge.key" --force >/dev/null 2>&1 ||
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 600 "$dir/munge/munge.key"
munge_socket="$dir/munge/munge.socket"
munged --force --foreground \
       --key-file="$dir/munge/munge.key" --socket="$munge_socket" \
       --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/munged.seed" \
       --log-file="$dir/munge/munged.log" \
       </dev/null >"$dir/log/munged.out" 2>&1 &
echo $! >"$dir/munged.pid"
for _ in $(seq 1 50); do
  [[ -S "$munge_socket" ]] && break
  kill -0 "$(cat "$dir/munged.pid")" 2>/dev/null || fail "munged exited at start (log: $dir/munge/munged.log)"
  sleep 0.1
done
[[ -S "$munge_socket" ]] || fail "munged did not create its socket $munge_socket within 5 s"
echo probe | munge --socket="$munge_socket" | unmunge --socket="$munge_socket" >/dev/null 2>&1 ||
  fail "munge cannot encode and decode a credential on $munge_socket"
note "munged ready on $munge_socket"

# ---- two TCP ports nobody listens on (IPv4 or IPv6), from a range away from ephemeral ports
listening_ports() {
  # /proc/net/tcp{,6}: "sl local_address rem_address st ...", the local address as HEXIP:HEXPORT,
  # state 0A = LISTEN.
  local sl local remote st rest
  cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | while read -r sl local remote st rest; do
    [[ "$st" == 0A ]] && echo $((16#${local##*:}))
  done
}
pick_ports() {
  local used base
  used=" $(listening_ports | tr '\n' ' ') "
  for _ in $(seq 1 200); do
    base=$((20000 + (RANDOM * 32768 + RANDOM) % 9000 * 2))
    if [[ "$used" != *" $base "* && "$used" != *" $((base + 1)) "* ]]; then
      echo "$base"
      return 0
    fi
  done
  return 1
}

node=$(hostname -s)
# The node's hardware as slurmd detects it (CPUs, sockets, cores, threads, memory), so the node
# registers without a mismatch that would drain it; falls back to nproc and /proc/meminfo.
node_hw=$(slurmd -C 2>/dev/null | head -n 1 | sed -n 's/^NodeName=[^ ]* //p' || true)
if [[ -z "$node_hw" ]]; then
  mem_mb=$(awk '/^MemTotal:/ { print int($2 / 1024) }' /proc/meminfo)
  node_hw="CPUs=$(nproc) RealMemory=$mem_mb"
fi

start_daemons() {
  local port=$1
  cat >"$dir/slurm.conf" <<EOF
# Private single-node cluster written by tests/slurm/start_slurm.sh; everything lives in $dir.
ClusterName=sbtest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$munge_socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/state/slurmctld.pid
SlurmdPidFile=$dir/spool/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
PlugStackConfig=$dir/plugstack.conf
MinJobAge=300
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 $node_hw State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  : >"$dir/plugstack.conf"
  cat >"$dir/env.sh" <<EOF
export SLURM_CONF=$dir/slurm.conf
EOF
  export SLURM_CONF="$dir/slurm.conf"
  : >"$dir/log/slurmctld.log"
  : >"$dir/log/slurmd.log"
  # -i: ignore state left in StateSaveLocation (it was just emptied anyway).
  setsid slurmctld -D -i -f "$SLURM_CONF" </dev/null >"$dir/log/slurmctld.out" 2>&1 &
  echo $! >"$dir/slurmctld.pid"
  setsid slurmd -D -f "$SLURM_CONF" -N "$node" </dev/null >"$dir/log/slurmd.out" 2>&1 &
  echo $! >"$dir/slurmd.pid"
}

# Waits until the node is idle. Returns 2 when a port was taken in the meantime (try other ports),
# 1 on any other failure (message in $why).
wait_idle() {
  local state
  for _ in $(seq 1 300); do
    for d in slurmctld slurmd; do
      if ! kill -0 "$(cat "$dir/$d.pid")" 2>/dev/null; then
        why="$d exited at start"
        if grep -qi "address already in use" "$dir/log/$d.log" "$dir/log/$d.out" 2>/dev/null; then
          return 2
        fi
        return 1
      fi
    done
    state=$(sinfo -h -n "$node" -o %T 2>/dev/null | head -n 1 || true)
    case "$state" in
      idle) return 0 ;;
      drain*|down*|fail*)
        why="node $node is $state: $(scontrol show node "$node" 2>/dev/null | grep -o 'Reason=.*' || true)"
        return 1 ;;
    esac
    sleep 0.1
  done
  why="node $node not idle within 30 s (last state: '${state:-no answer from slurmctld}')"
  return 1
}

started=0
for attempt in 1 2 3; do
  port=$(pick_ports) || fail "found no two free TCP ports in 20000..38000"
  start_daemons "$port"
  why=""
  rc=0
  wait_idle || rc=$?
  if [[ $rc -eq 0 ]]; then
    started=1
    break
  fi
  if [[ $rc -eq 2 && $attempt -lt 3 ]]; then
    for d in slurmd slurmctld; do
      kill "$(cat "$dir/$d.pid")" 2>/dev/null || true
      wait "$(cat "$dir/$d.pid")" 2>/dev/null || true
    done
    continue
  fi
  fail "$why"
done
[[ $started -eq 1 ]] || fail "could not start slurmctld and slurmd"
note "slurmctld (port $port) and slurmd (port $((port + 1))) up, node $node idle"

# A job must run end to end before the cluster is declared ready (squeue is polled: `sbatch --wait`
# polls with growing intervals and would add seconds).
probe=$(sbatch --parsable -o "$dir/log/probe.out" --wrap 'hostname' 2>&1) ||
  fail "sbatch of the probe job failed: $probe"
probe=${probe%%;*}
for _ in $(seq 1 300); do
  [[ -z "$(squeue -h -j "$probe" 2>/dev/null)" ]] && break
  sleep 0.1
done
probe_state=$(scontrol show job "$probe" 2>/dev/null | grep -o 'JobState=[A-Z_]*' || true)
[[ "$probe_state" == "JobState=COMPLETED" ]] ||
  fail "the probe job $probe (sbatch --wrap hostname) did not complete within 30 s: ${probe_state:-state unknown}"
[[ "$(cat "$dir/log/probe.out" 2>/dev/null)" == "$(hostname)" ]] ||
  fail "the probe job ran but wrote '$(cat "$dir/log/probe.out" 2>/dev/null)' instead of '$(hostname)'"
note "probe job ran on $node"

ready=1
cat "$dir/env.sh"
