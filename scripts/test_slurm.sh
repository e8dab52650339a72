#!/bin/bash
# A real test on a real Slurm: starts a one-node cluster on this machine (munged,
# slurmctld and slurmd with a generated slurm.conf, everything under a temporary folder
# and stopped at the end), submits a path-traced scene as an 8-task job array plus the
# merge job (scripts/slurm/submit.sh), and checks that the merged PNG and EXR are
# byte-identical to the render made in one go. Then it does it again with one task
# cancelled on purpose: the merge never runs, `submit.sh resubmit` sends only that task
# (and a new merge), and the image completes, byte-identical again.
#
# Installs Debian's slurm-wlm and munge with apt-get when they are missing (as root);
# when that cannot be done it says SKIPPED and exits 0. Exit 1 on any failure.
# Usage: scripts/test_slurm.sh   (LUCENT=path to use another binary)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
say() { echo "test_slurm: $*"; }
skip() { say "SKIPPED: $*"; exit 0; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    [ "$(id -u)" = 0 ] || skip "slurm-wlm and munge are not installed and this is not root"
    say "installing slurm-wlm and munge"
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null 2>&1 \
        || (apt-get update >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null 2>&1) \
        || skip "apt-get could not install slurm-wlm and munge"
fi
[ "$(id -u)" = 0 ] || skip "slurmd must run as root to start jobs as any user; run this as root"

lucent="${LUCENT:-$here/target/release/lucent}"
[ -x "$lucent" ] || (cd "$here" && cargo build --release -q)
lucent="$(realpath "$lucent")"

t="$(mktemp -d /tmp/lucent-slurm.XXXXXX)"
chmod 755 "$t"
host="$(hostname -s 2>/dev/null || cut -d. -f1 /proc/sys/kernel/hostname)"
cpus="$(nproc)"
port=$((20000 + RANDOM % 20000))
cleanup() {
    set +e
    [ -n "${SLURM_CONF:-}" ] && scontrol shutdown >/dev/null 2>&1
    sleep 1
    for p in slurmd slurmctld munged; do
        [ -f "$t/$p.pid" ] && kill "$(cat "$t/$p.pid")" 2>/dev/null
    done
    sleep 1
    rm -rf "$t"
}
trap cleanup EXIT

# munge: its own key, socket and files.
mkdir -p "$t/munge"
chmod 700 "$t/munge"
dd if=/dev/urandom of="$t/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$t/munge/munge.key"
munged --key-file="$t/munge/munge.key" --socket="$t/munge/munge.socket" \
    --pid-file="$t/munged.pid" --log-file="$t/munge/munged.log" --seed-file="$t/munge/munged.seed" --force \
    || skip "munged would not start here: $(tail -n 3 "$t/munge/munged.log" 2>/dev/null)"

mkdir -p "$t/state" "$t/spool" "$t/log"
cat >"$t/slurm.conf" <<CONF
ClusterName=lucenttest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$t/munge/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$t/state
SlurmdSpoolDir=$t/spool
SlurmctldPidFile=$t/slurmctld.pid
SlurmdPidFile=$t/slurmd.pid
SlurmctldLogFile=$t/log/slurmctld.log
SlurmdLogFile=$t/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SlurmdTimeout=300
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$t/slurm.conf"
# The cluster not starting is this machine's doing, not lucent's: a skip, with the logs.
slurmctld -f "$SLURM_CONF" || skip "slurmctld would not start: $(tail -n 5 "$t/log/slurmctld.log" 2>/dev/null)"
slurmd -f "$SLURM_CONF" || skip "slurmd would not start: $(tail -n 5 "$t/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
    sleep 1
done
sinfo -h -o %T | grep -qE '^(idle|mixed|allocated)' || skip "the node did not come up: $(tail -n 5 "$t/log/slurmd.log" 2>/dev/null)"
say "a one-node Slurm is up: $host, $cpus CPUs"

# The scene: path traced, a few seconds in all.
work="$t/work"
mkdir -p "$work"
cat >"$work/scene.test" <<'SCENE'
size 160 120
integrator pathtracer
spp 64
nexteventestimation mis
russianroulette on
gamma 2.2
camera 0 1 3 0 0.8 0 0 1 0 45
quadLight -0.25 1.999 -0.25 0 0 0.5 0.5 0 0 30 26 21
diffuse 0.7 0.7 0.7
maxverts 4
vertex -2 0 -2
vertex 2 0 -2
vertex 2 0 2
vertex -2 0 2
tri 0 2 1
tri 0 3 2
diffuse 0.2 0.6 0.3
sphere 0 0.5 0 0.4
transparent 1 1 1
ior 1.5
diffuse 0 0 0
sphere 0.5 0.3 0.4 0.25
SCENE
"$lucent" render "$work/scene.test" -o "$work/one.png" -q
"$lucent" render "$work/scene.test" -o "$work/one.exr" -q
"$lucent" render "$work/scene.test" -o "$work/one-aov.exr" --aov albedo,depth -q

wait_for() { # JOBID… : until none is pending or running
    for _ in $(seq 600); do
        [ -z "$(squeue -h -j "$(IFS=,; echo "$*")" 2>/dev/null)" ] && return 0
        sleep 1
    done
    say "jobs $* did not finish in 10 minutes"; exit 1
}
same() { cmp -s "$work/one.png" "$1/scene.png" && cmp -s "$work/one.exr" "$1/scene.exr"; }

# 1. Eight tasks and the merge, with auxiliary passes (the tasks keep their sums, the
#    merge writes them).
export LUCENT="$lucent"
SECONDS=0
"$here/scripts/slurm/submit.sh" render "$work/scene.test" 8 "$work/run1" --aov albedo,depth
. "$work/run1/submission.env"
wait_for "$array_job" "$merge_job"
took=$SECONDS
[ -e "$work/run1/scene.png" ] || { say "no merged image"; cat "$work/run1/"*.log; exit 1; }
cmp -s "$work/one.png" "$work/run1/scene.png" && cmp -s "$work/one-aov.exr" "$work/run1/scene.exr" \
    || { say "FAILED: the merged image differs from the one-go render"; exit 1; }
say "8 tasks + merge in ${took} s: merged PNG and EXR (with --aov albedo,depth) are byte-identical to the one-go render"

# 2. One task killed on purpose: held array, task 3 cancelled, the others released.
export SBATCH_OPTIONS="--hold"
"$here/scripts/slurm/submit.sh" render "$work/scene.test" 8 "$work/run2"
unset SBATCH_OPTIONS
. "$work/run2/submission.env"
scancel "${array_job}_3"
scontrol release "$array_job" >/dev/null 2>&1 || true
scontrol release "$merge_job" >/dev/null 2>&1 || true
for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$array_job" 2>/dev/null)" ] && break
    sleep 1
done
sleep 2
[ ! -e "$work/run2/task-3.lstate" ] || { say "task 3 ran though it was cancelled"; exit 1; }
[ ! -e "$work/run2/scene.png" ] || { say "the merge ran though a task failed"; exit 1; }
say "task 3 cancelled: 7 states, no merge (its dependency can never be met)"
"$here/scripts/slurm/submit.sh" resubmit "$work/run2"
. "$work/run2/submission.env"
wait_for "$array_job" "$merge_job"
same "$work/run2" || { say "FAILED: the image completed by resubmission differs from the one-go render"; exit 1; }
say "resubmitting only task 3 completed the image, byte-identical to the one-go render"

# 3. Batch mode: one array task per scene.
sed 's/^size 160 120/size 80 60/' "$work/scene.test" >"$work/small.test"
printf '%s\n' "$work/scene.test" "$work/small.test" >"$work/list.txt"
line="$("$here/scripts/slurm/submit.sh" batch "$work/list.txt" "$work/batch")"
echo "$line"
wait_for "$(echo "$line" | sed -n 's/.* array \([0-9]*\) .*/\1/p')"
cmp -s "$work/one.png" "$work/batch/scene.png" && [ -s "$work/batch/small.png" ] \
    || { say "FAILED: batch mode did not render both scenes"; exit 1; }
say "batch mode: 2 scenes, 2 array tasks, both rendered"
say "passed"
