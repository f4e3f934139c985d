#!/usr/bin/env bash
# Starts (or stops) a throw-away single-node Slurm cluster in a folder, for
# tests: munged with its own key and socket, slurmctld and slurmd with a
# generated slurm.conf (proctrack/linuxproc, task/none: no cgroups, no
# accounting), on non-default ports so that a real cluster on the machine is
# not disturbed. Needs Debian's slurm-wlm and munge (scripts/setup.sh) and
# root for the daemons (slurmd starts jobs as their users): run as root, or
# as a user with password-less sudo (the daemons then run through sudo).
#   scripts/slurm-cluster.sh start DIR   -> prints the slurm.conf path
#   scripts/slurm-cluster.sh stop DIR
set -euo pipefail
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo -n"; fi
cmd=${1:?usage: slurm-cluster.sh start|stop DIR}
D=$(realpath -m "${2:?usage: slurm-cluster.sh start|stop DIR}")
stop() {
  for p in slurmd slurmctld munge/munged; do
    if [ -f "$D/$p.pid" ]; then $SUDO kill "$(cat "$D/$p.pid")" 2>/dev/null || true; fi
  done
  sleep 1
}
if [ "$cmd" = stop ]; then stop; exit 0; fi
[ "$cmd" = start ] || { echo "usage: slurm-cluster.sh start|stop DIR" >&2; exit 2; }
for b in munged slurmctld slurmd sbatch; do
  command -v "$b" >/dev/null || { echo "slurm-cluster: $b not found (run scripts/setup.sh)" >&2; exit 1; }
done
mkdir -p "$D"/{state,spool,log,munge}
chmod 700 "$D/munge"
head -c 1024 /dev/urandom > "$D/munge/munge.key"
chmod 400 "$D/munge/munge.key"
$SUDO munged --force --key-file="$D/munge/munge.key" --socket="$D/munge/munge.socket" \
  --pid-file="$D/munge/munged.pid" --log-file="$D/log/munged.log" --seed-file="$D/munge/seed"
HOST=$(hostname -s)
CPUS=$(nproc)
MEM=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2 ))
PORT=${SLURM_TEST_PORT:-16817}
cat > "$D/slurm.conf" <<CONF
ClusterName=irsigtest
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$D/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$HOST CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
$SUDO slurmctld -f "$D/slurm.conf"
$SUDO slurmd -f "$D/slurm.conf"
# Wait for the node to come up (idle).
for _ in $(seq 60); do
  if SLURM_CONF="$D/slurm.conf" sinfo -h -o %t 2>/dev/null | grep -q idle; then
    echo "$D/slurm.conf"; exit 0
  fi
  sleep 1
done
echo "slurm-cluster: the node did not come up; logs:" >&2
$SUDO tail -n 30 "$D"/log/*.log >&2 || true
stop
exit 1
