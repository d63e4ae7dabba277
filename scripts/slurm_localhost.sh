#!/usr/bin/env bash
# A one-node Slurm cluster on this machine (controller and node daemon on localhost, as root),
# that runs a command as a batch job and is stopped afterwards: how the sbatch example of
# docs/user_guide/cluster.md is tried without a cluster.
# Usage: scripts/slurm_localhost.sh WORK_DIR SBATCH_ARGS...   (e.g. `... /tmp/slurm --ntasks=2 job.sbatch args`)
# Needs munge and Slurm's daemons (Debian's slurmctld, slurmd, slurm-client: scripts/install_deps.sh).
# Prints the job's log; exit status: the job's.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install_deps.sh"
work=$(mkdir -p "$1" && cd "$1" && pwd)
shift
host=$(hostname -s)
cpus=$(nproc)
memory_mb=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
mkdir -p "$work/state" "$work/spool" "$work/munge"
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=vvlocal
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF

# munged on its own socket, then the two Slurm daemons; each stopped by its pid on exit.
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done  # their last state written
}
trap cleanup EXIT
munged --foreground --force --socket="$work/munge/socket" --pid-file="$work/munge/pid" \
  --log-file="$work/munge/log" --seed-file="$work/munge/seed" &
pids+=($!)
sleep 1
slurmctld -D -f "$SLURM_CONF" &
pids+=($!)
slurmd -D -f "$SLURM_CONF" &
pids+=($!)
for _ in $(seq 30); do
  sinfo -h -o %T 2>/dev/null | grep -qE "idle|mixed" && break
  sleep 1
done
sinfo
rc=0
sbatch --wait --chdir="$work" --output="$work/job-%j.log" "$@" || rc=$?
cat "$work"/job-*.log
exit "$rc"
