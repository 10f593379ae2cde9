#!/usr/bin/env bash
# A throwaway single-node Slurm cluster (slurmctld, slurmd and a private
# munged, from Debian's packages) in directory DIR, for the batch test and
# benchmark; nothing outside DIR is touched and no system service is used.
#   slurm-local.sh start DIR   start; prints the SLURM_CONF to export
#   slurm-local.sh stop DIR    shut everything down and remove DIR
# Ports 16817/16818 (not Slurm's defaults). Jobs run as the caller (root).
# MinJobAge=4: `sbatch --wait` (Slurm 22.05) polls after 2 s and multiplies
# its interval by 4, up to 32 s, while the interval is under half of
# MinJobAge: with the default 300 s it polls at 2, 10, 42, 74 s..., and a
# job array that ends at 11 s was waited for until 42 s. With 4 it polls
# every 2 s (job records are kept 4 s after a job ends).
set -euo pipefail
cmd=${1:?start|stop}
T=${2:?directory}
case "$cmd" in
start)
  H=$(hostname -s)
  mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/log"
  chmod 755 "$T" "$T/munge"
  [ -f "$T/munge/munge.key" ] || mungekey -c -k "$T/munge/munge.key"
  munged --force -S "$T/munge/munge.socket" --key-file="$T/munge/munge.key" \
    --log-file="$T/log/munged.log" --pid-file="$T/munge/munged.pid" --seed-file="$T/munge/munged.seed"
  # proctrack/linuxproc and task/none: no cgroups (containers have no freezer).
  cat > "$T/slurm.conf" <<CONF
ClusterName=navcamtest
SlurmctldHost=$H(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.socket
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SchedulerType=sched/backfill
MinJobAge=4
NodeName=$H NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$T/slurm.conf"
  slurmctld -f "$SLURM_CONF"
  slurmd -f "$SLURM_CONF"
  for _ in $(seq 150); do
    if sinfo -h -N -o %t 2>/dev/null | grep -qx idle; then
      echo "$SLURM_CONF"
      exit 0
    fi
    sleep 0.2
  done
  echo "slurm-local: the node did not become idle in 30 s" >&2
  cat "$T"/log/*.log >&2 || true
  exit 1
  ;;
stop)
  export SLURM_CONF="$T/slurm.conf"
  scontrol shutdown >/dev/null 2>&1 || true
  for f in "$T/slurmctld.pid" "$T/slurmd.pid"; do
    [ -f "$f" ] || continue
    p=$(cat "$f")
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.2; done
    kill -9 "$p" 2>/dev/null || true
  done
  munged -s -S "$T/munge/munge.socket" >/dev/null 2>&1 ||
    { [ -f "$T/munge/munged.pid" ] && kill "$(cat "$T/munge/munged.pid")" 2>/dev/null; } || true
  rm -rf "$T"
  ;;
*) echo "slurm-local: start or stop, not '$cmd'" >&2; exit 2 ;;
esac
