#!/bin/bash
# A private single-node Slurm cluster on loopback, for tests and trying the scripts out:
# its own munged, slurmctld and slurmd, configuration, state and logs all under DIR (nothing
# of the system's Slurm or munge configuration is touched). Needs root (slurmd) and Debian's
# slurm-wlm and munge (`./egress.sh deps-slurm` installs them).
#
#   deploy/slurm/local-cluster.sh start DIR [CPUS]   # prints: export SLURM_CONF=DIR/slurm.conf
#   deploy/slurm/local-cluster.sh stop DIR
set -euo pipefail
command=${1:?start|stop}
dir=${2:?DIR}
die() { echo "local-cluster.sh: error: $*" >&2; exit 2; }

stop() {
  for daemon in slurmd slurmctld munged; do
    if [ -f "$dir/$daemon.pid" ]; then
      pid=$(cat "$dir/$daemon.pid")
      kill "$pid" 2> /dev/null || true
      for _ in $(seq 1 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
      rm -f "$dir/$daemon.pid"
    fi
  done
}

case "$command" in
  stop) stop; exit 0 ;;
  start) ;;
  *) die "unknown command '$command' (start or stop)" ;;
esac
for tool in munged mungekey slurmctld slurmd sinfo; do
  command -v "$tool" > /dev/null || die "'$tool' not found: install slurm-wlm and munge"
done
[ "$(id -u)" = 0 ] || die "slurmd needs root"
cpus=${3:-$(nproc)}
mkdir -p "$dir"/{state,spool,munge}
dir=$(cd "$dir" && pwd)
# munged's socket path must fit a sockaddr_un (108 bytes, with room for its lock file).
[ ${#dir} -le 80 ] || die "'$dir' is too long for munge's socket path (at most 80 characters)"
# Free TCP ports for the controller and the node daemon.
ports=$(python3 - << 'PY' 2> /dev/null || echo "16817 16818"
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])
PY
)
read -r ctld_port node_port <<< "$ports"
chmod 700 "$dir/munge"
[ -f "$dir/munge/munge.key" ] || mungekey --create --keyfile "$dir/munge/munge.key" > /dev/null
chmod 600 "$dir/munge/munge.key"
munged --force --key-file "$dir/munge/munge.key" --socket "$dir/munge/munge.socket" \
  --pid-file "$dir/munged.pid" --log-file "$dir/munged.log" --seed-file "$dir/munge/seed" \
  < /dev/null > /dev/null 2>&1
host=$(hostname -s)
cat > "$dir/slurm.conf" << CONF
ClusterName=egress-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$node_port
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
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
NodeName=egress-node NodeHostname=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=egress Nodes=egress-node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld -i < /dev/null > /dev/null 2>&1
slurmd -N egress-node < /dev/null > /dev/null 2>&1
# Ready when the node is idle.
for _ in $(seq 1 100); do
  if sinfo -h -o %T 2> /dev/null | grep -q idle; then
    echo "export SLURM_CONF=$dir/slurm.conf"
    exit 0
  fi
  sleep 0.2
done
echo "local-cluster.sh: the cluster did not come up; logs in $dir:" >&2
tail -n 5 "$dir"/*.log >&2 || true
stop
exit 1
