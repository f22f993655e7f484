#!/usr/bin/env bash
# Starts a one-node Slurm on this machine (Debian's slurm-wlm + munge) for the
# `validation` test that submits a study's slurm.sbatch, and for trying --plan
# locally. Needs root (or sudo). Idempotent: a second call finds it running.
#   bash scripts/local-slurm.sh          # install if missing, configure, start
#   bash scripts/local-slurm.sh stop     # stop the daemons
set -euo pipefail
sudo_cmd=""
[ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"

if [ "${1:-}" = "stop" ]; then
  $sudo_cmd pkill -x slurmd || true
  $sudo_cmd pkill -x slurmctld || true
  $sudo_cmd pkill -x munged || true
  exit 0
fi

missing=()
for p in slurm-wlm munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y --no-install-recommends "${missing[@]}" >&2
fi

host=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo)
$sudo_cmd mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
$sudo_cmd tee /etc/slurm/slurm.conf > /dev/null <<CONF
# One-node Slurm for rocklab's tests (scripts/local-slurm.sh).
ClusterName=rocklab
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=${host} NodeAddr=127.0.0.1 CPUs=${cpus} RealMemory=${mem} State=UNKNOWN
PartitionName=local Nodes=${host} Default=YES MaxTime=INFINITE State=UP
CONF

$sudo_cmd mkdir -p /run/munge /var/log/munge /var/lib/munge
$sudo_cmd chown -R munge:munge /run/munge /var/log/munge /var/lib/munge /etc/munge
pgrep -x munged > /dev/null || $sudo_cmd su -s /bin/sh munge -c munged
pgrep -x slurmctld > /dev/null || $sudo_cmd slurmctld
pgrep -x slurmd > /dev/null || $sudo_cmd slurmd
for _ in $(seq 1 30); do
  if sinfo -h -o "%T" 2>/dev/null | grep -qE "idle|mixed|allocated"; then
    sinfo
    exit 0
  fi
  sleep 1
done
echo "local-slurm: the node did not come up; see /var/log/slurm/" >&2
sinfo >&2 || true
exit 1
