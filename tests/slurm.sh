#!/usr/bin/env bash
# A real single-node SLURM (Debian's slurm-wlm with munge) in a scratch folder: runs the
# documented job array (docs/cluster/slurm-array.sbatch, 4 tasks) and merge step
# (slurm-merge.sbatch, after the array), then compares the table with a single bake.
# Usage: slurm.sh CLOTHBAKE FABRIC.json DOCS_CLUSTER_DIR. Exit 0: identical tables.
# The daemons run in the foreground of background jobs and are stopped by their PIDs on exit,
# whatever happens (trap EXIT).
set -euo pipefail
BIN=$1 FABRIC=$2 DOCS=$3
P=$(mktemp -d "${TMPDIR:-/tmp}/clothbake-slurm.XXXXXX")
PIDS=()
cleanup() {
    local rc=$?
    for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${PIDS[@]}"; do
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
    done
    if [ $rc -ne 0 ]; then
        echo "--- slurmctld log"; tail -n 20 "$P/log/slurmctld.log" 2>/dev/null || true
        echo "--- slurmd log"; tail -n 20 "$P/log/slurmd.log" 2>/dev/null || true
        for f in "$P"/work/*.log; do [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done
    fi
    rm -rf "$P"
    exit $rc
}
trap cleanup EXIT

chmod 755 "$P"   # munged wants the socket's folders searchable by all (mktemp gives 700)
mkdir -p "$P"/munge/{etc,run,lib,log} "$P"/{etc,state,spool,log,work}
chmod 700 "$P"/munge/etc "$P"/munge/lib "$P"/munge/log
chmod 755 "$P"/munge "$P"/munge/run
mungekey --create --keyfile="$P/munge/etc/munge.key" --bits=1024
munged --foreground --key-file="$P/munge/etc/munge.key" --socket="$P/munge/run/munge.socket.2" \
    --pid-file="$P/munge/run/munged.pid" --seed-file="$P/munge/lib/munged.seed" \
    --log-file="$P/munge/log/munged.log" >"$P/munge/log/stdout" 2>&1 &
PIDS+=($!)
for i in $(seq 100); do
    [ -S "$P/munge/run/munge.socket.2" ] && break
    [ "$i" = 100 ] && { echo "munged did not start"; exit 1; }
    sleep 0.05
done

H=$(hostname -s)
CPUS=$(slurmd -C | sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' | head -n1)
cat > "$P/etc/slurm.conf" <<CONF
ClusterName=local
SlurmctldHost=$H
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$P/munge/run/munge.socket.2
StateSaveLocation=$P/state
SlurmdSpoolDir=$P/spool
SlurmctldPidFile=$P/slurmctld.pid
SlurmdPidFile=$P/slurmd.pid
SlurmctldLogFile=$P/log/slurmctld.log
SlurmdLogFile=$P/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
ReturnToService=2
NodeName=$H CPUs=${CPUS:-1} RealMemory=4000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$P/etc/slurm.conf
slurmctld -D -f "$SLURM_CONF" >"$P/log/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" >"$P/log/slurmd.out" 2>&1 &
PIDS+=($!)
for i in $(seq 100); do
    timeout 2 sinfo -h -o %T 2>/dev/null | grep -qx idle && break
    [ "$i" = 100 ] && { echo "SLURM did not come up in 10 s"; exit 1; }
    sleep 0.1
done

cd "$P/work"
export CLOTHBAKE=$BIN WEAVE=$FABRIC SHARDS=$P/work/shards TABLE=$P/work/merged.bin
export BAKE_OPTS="--res 8,16,8,16"
# Four tasks of one CPU each: two at a time on two cores. Command-line options override the
# script's #SBATCH lines.
JID=$(sbatch --parsable --array=0-3 --cpus-per-task=1 "$DOCS/slurm-array.sbatch")
MID=$(sbatch --parsable --dependency=afterok:"$JID" "$DOCS/slurm-merge.sbatch")
for i in $(seq 600); do
    [ -z "$(timeout 5 squeue -h -j "$JID,$MID" 2>/dev/null)" ] && break
    [ "$i" = 600 ] && { echo "the jobs did not finish in 60 s"; squeue; exit 1; }
    sleep 0.1
done
for k in 0 1 2 3; do
    grep -q "shard $k/4 from SLURM_ARRAY_TASK_ID=$k" "$P/work/clothbake-${JID}_$k.log" 2>/dev/null ||
        { echo "task $k did not report its shard"; exit 1; }
done
[ -f merged.bin ] || { echo "the merge job wrote no table"; exit 1; }
"$BIN" bake --weave "$FABRIC" $BAKE_OPTS -o single.bin --quiet
"$BIN" diff single.bin merged.bin --tol 0 --abs 0
cmp single.bin merged.bin
echo "SLURM job array $JID (4 shards) and merge job $MID: merged table identical to a single bake"
