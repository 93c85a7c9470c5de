#!/usr/bin/env bash
# A one-node SLURM cluster in a folder of its own, for the tests that run docs/batch.md's SLURM
# lines (Debian's slurm-wlm and munge; nothing outside FOLDER is written or read but the
# programs).
#
#   one-node-slurm.sh start FOLDER   # munged, slurmctld and slurmd, on free ports; waits until
#                                    # the node takes jobs; prints SLURM_CONF=FOLDER/slurm.conf
#   one-node-slurm.sh stop FOLDER    # ends all three (also after a start that failed half-way)
#
# start exits 2 with one line on stderr when a program is missing, 1 when the cluster does not
# come up (with the daemons' last log lines), 0 when it takes jobs.
set -euo pipefail

command=${1:-}
folder=${2:-}
if [ -z "$command" ] || [ -z "$folder" ]; then
  echo "usage: one-node-slurm.sh start|stop FOLDER" >&2
  exit 2
fi
folder=$(realpath -m "$folder")
conf=$folder/slurm.conf
socket=$folder/munge/socket
# slurmd's step sockets (FOLDER/spool/NODE_JOB.STEP) must fit a Unix socket path (108 bytes).
if [ "$command" = start ] && [ ${#folder} -gt 60 ]; then
  echo "one-node-slurm.sh: the folder's path is ${#folder} characters, more than 60: slurmd's sockets in it would not fit" >&2
  exit 2
fi

stop() {
  if [ -s "$conf" ] && command -v scontrol > /dev/null; then
    SLURM_CONF=$conf timeout 10 scontrol shutdown > /dev/null 2>&1 || true
  fi
  # Whatever is left (a daemon that never answered), by the pid files it wrote.
  for pid_file in "$folder/slurmctld.pid" "$folder/slurmd.pid" "$folder/munge/munged.pid"; do
    if [ -s "$pid_file" ]; then kill "$(cat "$pid_file")" > /dev/null 2>&1 || true; fi
  done
  for _ in $(seq 50); do
    alive=0
    for pid_file in "$folder/slurmctld.pid" "$folder/slurmd.pid" "$folder/munge/munged.pid"; do
      if [ -s "$pid_file" ] && kill -0 "$(cat "$pid_file")" 2> /dev/null; then alive=1; fi
    done
    [ "$alive" = 1 ] || return 0
    sleep 0.1
  done
  # Still there after 5 s: ended for good.
  for pid_file in "$folder/slurmctld.pid" "$folder/slurmd.pid" "$folder/munge/munged.pid"; do
    if [ -s "$pid_file" ]; then kill -KILL "$(cat "$pid_file")" > /dev/null 2>&1 || true; fi
  done
}

if [ "$command" = stop ]; then
  stop
  exit 0
fi
[ "$command" = start ] || { echo "one-node-slurm.sh: unknown command '$command'" >&2; exit 2; }

for program in munged slurmctld slurmd sbatch sinfo scontrol python3; do
  command -v "$program" > /dev/null || { echo "$program is not installed (Debian: slurm-wlm, munge)" >&2; exit 2; }
done

# From here on, a step that fails stops what was started, with the daemons' last log lines.
failed() {
  echo "one-node-slurm.sh: start failed: $(tail -q -n 3 "$folder"/log/* "$folder"/munge/*.log 2> /dev/null | tr '\n' ' ')" >&2
  stop
}
trap 'failed; exit 1' ERR

# munge: a key of its own, its socket in the folder (slurm.conf's AuthInfo names it).
mkdir -p "$folder/munge" "$folder/state" "$folder/spool" "$folder/log"
chmod 700 "$folder/munge"
head -c 1024 /dev/urandom > "$folder/munge/key"
chmod 400 "$folder/munge/key"
if ! munged --force --key-file="$folder/munge/key" --socket="$socket" --pid-file="$folder/munge/munged.pid" \
  --log-file="$folder/munge/munged.log" --seed-file="$folder/munge/seed" > "$folder/log/munged.out" 2>&1; then
  echo "munged did not start: $(tail -n 3 "$folder/log/munged.out" "$folder/munge/munged.log" 2> /dev/null | tr '\n' ' ')" >&2
  exit 1
fi

# Two free TCP ports for slurmctld and slurmd (asked of the kernel, then let go).
read -r control_port node_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
node=$(hostname -s)
user=$(id -un)
cat > "$conf" << EOF
ClusterName=animorder
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$control_port
SlurmdPort=$node_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
SlurmUser=$user
SlurmdUser=$user
StateSaveLocation=$folder/state
SlurmdSpoolDir=$folder/spool
SlurmctldPidFile=$folder/slurmctld.pid
SlurmdPidFile=$folder/slurmd.pid
SlurmctldLogFile=$folder/log/slurmctld.log
SlurmdLogFile=$folder/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
# Tasks scheduled as soon as they can run, up to 8 a CPU: an array of tiny tasks takes seconds,
# not a scheduling cycle each.
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
ReturnToService=2
MpiDefault=none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc)
PartitionName=main Nodes=$node Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:8
EOF
export SLURM_CONF=$conf
if ! slurmctld > "$folder/log/slurmctld.out" 2>&1 || ! slurmd > "$folder/log/slurmd.out" 2>&1; then
  echo "slurmctld or slurmd did not start: $(tail -q -n 3 "$folder"/log/*.out "$folder"/log/*.log 2> /dev/null | tr '\n' ' ')" >&2
  stop
  exit 1
fi
trap - ERR  # the checks below say what went wrong themselves
for _ in $(seq 300); do
  state=$(sinfo --noheader --nodes="$node" --format=%t 2> /dev/null || true)
  if [ "$state" = idle ]; then
    echo "SLURM_CONF=$conf"
    exit 0
  fi
  sleep 0.1
done
echo "the node did not take jobs within 30 s (state '${state:-none}'): $(tail -q -n 3 "$folder"/log/*.log 2> /dev/null | tr '\n' ' ')" >&2
stop
exit 1
