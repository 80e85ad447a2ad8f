#!/usr/bin/env bash
# A single-node Slurm on this machine, entirely inside DIR (its own munge
# key and socket, config, state, spool and logs; nothing under /etc): for
# trying docs/cluster/submit.sh, and for the test that does
# (tb/tests/sweep_plan.rs). Needs root and the Debian packages slurm-wlm and
# munge.
#   docs/cluster/local-slurm.sh start DIR   # then: export SLURM_CONF=DIR/slurm.conf
#   docs/cluster/local-slurm.sh stop DIR
set -euo pipefail
cmd=${1:?usage: local-slurm.sh start|stop DIR}
dir=$(mkdir -p "${2:?usage: local-slurm.sh start|stop DIR}" && cd "$2" && pwd)
stop() {
  for p in slurmd slurmctld munged; do
    if [ -f "$dir/$p.pid" ]; then kill "$(cat "$dir/$p.pid")" 2>/dev/null || true; fi
  done
}
case $cmd in
stop) stop; exit 0 ;;
start) ;;
*) echo "local-slurm.sh: unknown command $cmd (start or stop)" >&2; exit 2 ;;
esac
for b in munged slurmctld slurmd sinfo; do
  command -v $b >/dev/null || { echo "local-slurm.sh: $b not found (apt-get install slurm-wlm munge)" >&2; exit 1; }
done
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 8 / 10 ))
head -c 1024 /dev/urandom > "$dir/munge.key"
chmod 400 "$dir/munge.key"
munged --force --key-file="$dir/munge.key" --socket="$dir/munge.socket" \
  --pid-file="$dir/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munged.seed"
# Ports of our own, away from a Slurm the machine may run.
port=${LOCAL_SLURM_PORT:-26817}
cat > "$dir/slurm.conf" <<CONF
ClusterName=morphosys-local
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$dir/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  if sinfo -h -o %t 2>/dev/null | grep -q idle; then
    echo "slurm up on $host ($cpus CPUs): export SLURM_CONF=$SLURM_CONF"
    exit 0
  fi
  sleep 0.5
done
echo "local-slurm.sh: the node did not come up; see $dir/log" >&2
stop
exit 1
