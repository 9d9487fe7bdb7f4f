#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, from Debian's packages (slurm-wlm,
# munge), for the sweep tests and for trying `mjslam sweep --backend slurm`
# without a real cluster.
#
#   scripts/slurm_localhost.sh start    # installs what is missing, starts munged,
#                                       # slurmctld and slurmd; waits until the node is idle
#   scripts/slurm_localhost.sh status   # sinfo of the cluster
#   scripts/slurm_localhost.sh stop     # stops the daemons it started
#   scripts/slurm_localhost.sh env      # prints `export SLURM_CONF=...`
#
# Everything lives under $MJSLAM_SLURM_DIR (default /tmp/mjslam-slurm): the
# slurm.conf written for this machine's cores and memory, the spool and state
# directories, the daemons' logs and pid files. Slurm's commands find the
# cluster through SLURM_CONF (`eval "$(scripts/slurm_localhost.sh env)"`).
# Needs root (the daemons run as root, as on a single-user test node).
set -euo pipefail

dir=${MJSLAM_SLURM_DIR:-/tmp/mjslam-slurm}
conf=$dir/slurm.conf
node=$(hostname -s)

install_missing() {
  local missing=()
  for package in slurm-wlm munge; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$package")
    fi
  done
  if ((${#missing[@]} > 0)); then
    echo "slurm_localhost: installing ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
}

write_conf() {
  local cpus memory_mb
  cpus=$(nproc)
  # Leave a tenth of the memory to the system.
  memory_mb=$(awk '/MemTotal/ {printf "%d", $2 / 1024 * 0.9}' /proc/meminfo)
  mkdir -p "$dir/state" "$dir/spool" "$dir/log"
  cat > "$conf" <<EOF
# Written by scripts/slurm_localhost.sh for $node ($cpus CPUs, $memory_mb MB).
ClusterName=mjslam-localhost
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
# Short timeouts: a test cluster should notice a killed task at once.
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=300
KillWait=5
Waittime=0
# A job that asks for no memory gets its CPUs' share, so that jobs share the node.
DefMemPerCPU=$((memory_mb / cpus))
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
}

start_munge() {
  if pgrep -x munged >/dev/null; then return; fi
  mkdir -p /run/munge
  chown munge:munge /run/munge 2>/dev/null || true
  if [[ ! -s /etc/munge/munge.key ]]; then
    mungekey --create --keyfile /etc/munge/munge.key
    chown munge:munge /etc/munge/munge.key
  fi
  # As root: munged refuses to run as root unless forced.
  munged --force
}

stop_daemon() {
  local pidfile=$1
  if [[ -f $pidfile ]]; then
    local pid
    pid=$(cat "$pidfile")
    if kill "$pid" 2>/dev/null; then
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    fi
    rm -f "$pidfile"
  fi
}

start() {
  install_missing
  write_conf
  start_munge
  export SLURM_CONF=$conf
  stop_daemon "$dir/slurmd.pid"
  stop_daemon "$dir/slurmctld.pid"
  # -i: ignore state saved by an earlier cluster (clean queue each start).
  slurmctld -f "$conf" -i
  slurmd -f "$conf"
  # Wait until the node takes jobs.
  for _ in $(seq 60); do
    local state
    state=$(sinfo -h -N -o "%t" 2>/dev/null | head -n 1 || true)
    if [[ $state == idle* || $state == mix* || $state == alloc* ]]; then
      echo "slurm_localhost: node $node is $state ($conf)"
      return 0
    fi
    if [[ $state == down* || $state == drain* ]]; then
      scontrol update nodename="$node" state=resume 2>/dev/null || true
    fi
    sleep 0.5
  done
  echo "slurm_localhost: the node did not come up; see $dir/log/" >&2
  tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2 || true
  return 1
}

stop() {
  stop_daemon "$dir/slurmd.pid"
  stop_daemon "$dir/slurmctld.pid"
  echo "slurm_localhost: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) SLURM_CONF=$conf sinfo ;;
  env) echo "export SLURM_CONF=$conf" ;;
  *)
    echo "usage: $0 start|stop|status|env" >&2
    exit 2
    ;;
esac
