#!/usr/bin/env bash
# A single-node Slurm cluster in a directory of its own, for tests and
# benchmarks of `lumis slurm` on one machine (containers included: no
# systemd, no cgroups).
#
#   local-cluster.sh start DIR   install slurm-wlm and munge if missing, write
#                                DIR/etc/slurm.conf and a munge key, start
#                                munged, slurmctld and slurmd, wait until the
#                                node is idle; prints `export SLURM_CONF=...`
#   local-cluster.sh stop DIR    stop the daemons started in DIR
#   local-cluster.sh env DIR     print `export SLURM_CONF=...` for DIR
#
# With LOCAL_CLUSTER_INSTALL=0 it never installs packages (a test's
# choice: installing is for the machine's setup, e.g. .ci/run).
#
# Everything the cluster writes (key, state, spool, logs, pid files, socket)
# lives under DIR. The daemons run as the calling user. Exit status 2 means
# Slurm cannot run here (packages missing and not installable, a daemon
# failed); the reason is on stderr with the end of the daemon's log.
set -euo pipefail

usage() {
  echo "usage: $0 start|stop|env DIR" >&2
  exit 64
}
[ $# -eq 2 ] || usage
mode=$1
mkdir -p "$2"
dir=$(cd "$2" && pwd)
conf=$dir/etc/slurm.conf

cannot_run() {
  echo "local-cluster: cannot run Slurm here: $*" >&2
  exit 2
}

show_log() {
  if [ -s "$1" ]; then
    echo "--- last lines of $1:" >&2
    tail -n 15 "$1" >&2
  fi
}

install_packages() {
  local need=()
  for tool in munged slurmctld slurmd sbatch; do
    command -v "$tool" >/dev/null 2>&1 || PATH=$PATH:/usr/sbin command -v "$tool" >/dev/null 2>&1 || need+=("$tool")
  done
  [ ${#need[@]} -eq 0 ] && return 0
  [ "${LOCAL_CLUSTER_INSTALL:-1}" = 0 ] && cannot_run "missing ${need[*]}: install the Debian packages slurm-wlm and munge"
  echo "local-cluster: missing ${need[*]}; installing slurm-wlm and munge" >&2
  command -v apt-get >/dev/null 2>&1 || cannot_run "missing ${need[*]} and no apt-get to install slurm-wlm and munge"
  [ "$(id -u)" -eq 0 ] || cannot_run "missing ${need[*]}; install slurm-wlm and munge (needs root)"
  export DEBIAN_FRONTEND=noninteractive
  { apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null 2>&1 ||
    { apt-get update -qq >/dev/null 2>&1 &&
      apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null 2>&1; }; } ||
    cannot_run "apt-get install slurm-wlm munge failed"
}

# A TCP port nothing listens on, from $1 upwards.
free_port() {
  local port=$1
  while (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; do
    port=$((port + 1))
  done
  echo "$port"
}

pid_alive() {
  [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null
}

write_config() {
  local host cpus user ctld_port slurmd_port
  host=$(hostname -s)
  cpus=$(nproc)
  user=$(id -un)
  ctld_port=$(free_port 16817)
  slurmd_port=$(free_port $((ctld_port + 1)))
  mkdir -p "$dir/etc" "$dir/state" "$dir/spool" "$dir/log" "$dir/run" "$dir/munge"
  chmod 0700 "$dir/munge"
  cat >"$conf" <<CONF
# Written by local-cluster.sh: one node, no accounting, no cgroups. The
# daemons talk over 127.0.0.1, so the hostname need not resolve.
ClusterName=lumis-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=$user
SlurmdUser=$user
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
}

start_munge() {
  local key=$dir/munge/munge.key
  if [ ! -s "$key" ]; then
    dd if=/dev/urandom of="$key" bs=1024 count=1 status=none
    chmod 0400 "$key"
  fi
  pid_alive "$dir/run/munged.pid" && return 0
  munged --force \
    --key-file="$key" \
    --socket="$dir/munge/munge.socket" \
    --pid-file="$dir/run/munged.pid" \
    --seed-file="$dir/munge/munged.seed" \
    --log-file="$dir/log/munged.log" 2>>"$dir/log/munged.log" ||
    { show_log "$dir/log/munged.log"; cannot_run "munged failed to start"; }
  # A credential round trip proves the daemon answers on our socket.
  if ! munge -n --socket="$dir/munge/munge.socket" | unmunge --socket="$dir/munge/munge.socket" >/dev/null 2>&1; then
    show_log "$dir/log/munged.log"
    cannot_run "munged started but does not answer on $dir/munge/munge.socket"
  fi
}

start_slurm() {
  export SLURM_CONF=$conf
  if ! pid_alive "$dir/run/slurmctld.pid"; then
    slurmctld -f "$conf" >>"$dir/log/slurmctld.out" 2>&1 ||
      { show_log "$dir/log/slurmctld.log"; show_log "$dir/log/slurmctld.out"; cannot_run "slurmctld failed to start"; }
  fi
  if ! pid_alive "$dir/run/slurmd.pid"; then
    slurmd -f "$conf" >>"$dir/log/slurmd.out" 2>&1 ||
      { show_log "$dir/log/slurmd.log"; show_log "$dir/log/slurmd.out"; cannot_run "slurmd failed to start"; }
  fi
  local state=""
  for _ in $(seq 1 60); do
    state=$(sinfo -h -N -o %t 2>/dev/null | head -n 1 || true)
    case $state in
      idle | mix | alloc) return 0 ;;
    esac
    sleep 0.5
  done
  show_log "$dir/log/slurmctld.log"
  show_log "$dir/log/slurmd.log"
  cannot_run "the node did not become idle within 30 s (sinfo state: '${state:-none}')"
}

stop_all() {
  local pids=()
  for name in slurmd slurmctld munged; do
    local file=$dir/run/$name.pid
    if pid_alive "$file"; then
      pids+=("$(cat "$file")")
      kill "$(cat "$file")" 2>/dev/null || true
    fi
    rm -f "$file"
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 1 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$pid" 2>/dev/null || true
  done
}

case $mode in
  start)
    PATH=$PATH:/usr/sbin:/sbin
    install_packages
    [ -f "$conf" ] || write_config
    start_munge
    start_slurm
    echo "export SLURM_CONF=$conf"
    ;;
  stop) stop_all ;;
  env) echo "export SLURM_CONF=$conf" ;;
  *) usage ;;
esac
