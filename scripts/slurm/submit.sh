#!/bin/bash
# Sends lucent renders to Slurm.
#
#   submit.sh render SCENE N OUTDIR [render options…]
#       cuts SCENE into N tasks (`lucent plan --measure`, kept in OUTDIR/plan.json and
#       plan.txt), submits them as a job array
#       (--array=0-(N-1), task I runs `lucent render SCENE --task I/N`) and a merge job
#       that runs when all of them succeed (--dependency=afterok): OUTDIR/<scene>.png,
#       .exr and .lstate. With --aov or --denoise the merge makes the passes (in the EXR,
#       and <scene>.aovs.exr beside the PNG) and the denoised picture.
#   submit.sh resubmit OUTDIR
#       submits again only the tasks whose state is missing (failed, cancelled, killed
#       with their node), and a new merge job after them.
#   submit.sh batch LIST OUTDIR [render options…]
#       one array task per scene file named in LIST (one per line): OUTDIR/<scene>.png.
#
# Environment: LUCENT (the lucent binary; default: lucent on PATH, else this checkout's
# target/release/lucent), SBATCH_OPTIONS (more sbatch options for every job, e.g.
# "--partition=long --time=2:00:00 --cpus-per-task=8"). Render options must not contain
# spaces. What was submitted is kept in OUTDIR/submission.env.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
lucent="${LUCENT:-$(command -v lucent || echo "$here/../../target/release/lucent")}"
lucent="$(realpath "$lucent")"
opts=(${SBATCH_OPTIONS:-})

# sbatch_job NAME ARGS… : submits, prints the job id.
sbatch_job() { sbatch --parsable "${opts[@]}" "$@" | cut -d';' -f1; }

# The jobs get their settings through the environment (--export=ALL): values may hold
# commas, which --export=NAME=VALUE lists cannot.
# The render options split between the tasks and the merge: the passes (--aov) and
# denoising (--denoise) are made by the merge from the states, which keep the passes' sums
# (a task writes no picture: --denoise there becomes --aov albedo,normal, the passes the
# denoiser reads). Sets task_args and merge_args from args.
split_args() {
    local a aov="" denoise="" next=""
    task_args=""; merge_args=""
    for a in $args; do
        if [ -n "$next" ]; then aov="$a"; next=""; continue; fi
        case "$a" in
            --denoise) denoise=1 ;;
            --aov) next=1 ;;
            --aov=*) aov="${a#--aov=}" ;;
            *) task_args+=" $a" ;;
        esac
    done
    if [ -n "$aov" ]; then task_args+=" --aov $aov"; merge_args+=" --aov $aov"; fi
    if [ -n "$denoise" ]; then
        merge_args+=" --denoise"
        [ -n "$aov" ] || task_args+=" --aov albedo,normal"
    fi
    task_args="${task_args# }"; merge_args="${merge_args# }"
}

submit_merge() { # [DEPENDENCY]
    LUCENT="$lucent" LUCENT_OUT="$out" LUCENT_NAME="$name" LUCENT_TASKS="$tasks" LUCENT_MERGE_ARGS="$merge_args" \
        sbatch_job ${1:+--dependency="$1"} --output="$out/merge-%j.log" --export=ALL "$here/merge.sbatch"
}

submit_tasks() { # ARRAY_SPEC
    LUCENT="$lucent" LUCENT_SCENE="$scene" LUCENT_TASKS="$tasks" LUCENT_OUT="$out" \
        LUCENT_ARGS="$task_args --plan $out/plan.json" \
        sbatch_job --array="$1" --output="$out/task-%a.log" --export=ALL "$here/render-task.sbatch"
}

save() {
    cat >"$out/submission.env" <<ENV
scene='$scene'
tasks='$tasks'
name='$name'
args='$args'
array_job='$array_job'
merge_job='$merge_job'
ENV
}

case "${1:-}" in
render)
    [ $# -ge 4 ] || { echo "usage: submit.sh render SCENE N OUTDIR [render options…]" >&2; exit 2; }
    scene="$(realpath "$2")"; tasks="$3"; out="$4"; shift 4; args="$*"
    mkdir -p "$out"; out="$(realpath "$out")"
    name="$(basename "${scene%.*}")"
    split_args
    # The plan, for the record (and a check that the scene and options are good).
    # shellcheck disable=SC2086
    # Bands (if any) balanced by the measured time of a probe; the tasks read this plan.
    "$lucent" plan "$scene" --tasks "$tasks" $task_args --measure --json "$out/plan.json" -q >"$out/plan.txt"
    array_job="$(submit_tasks "0-$((tasks - 1))")"
    merge_job="$(submit_merge "afterok:$array_job")"
    save
    echo "submitted: tasks $array_job (array 0-$((tasks - 1))), merge $merge_job -> $out/$name.png"
    ;;
resubmit)
    [ $# -eq 2 ] || { echo "usage: submit.sh resubmit OUTDIR" >&2; exit 2; }
    out="$(realpath "$2")"
    # shellcheck disable=SC1091
    . "$out/submission.env"
    split_args
    missing=()
    for ((i = 0; i < tasks; i++)); do [ -e "$out/task-$i.lstate" ] || missing+=("$i"); done
    # The old merge waits for tasks that will never succeed: it goes.
    scancel "$merge_job" 2>/dev/null || true
    if [ ${#missing[@]} -eq 0 ]; then
        merge_job="$(submit_merge)"
        echo "every task is done; merge $merge_job"
    else
        spec="$(IFS=,; echo "${missing[*]}")"
        array_job="$(submit_tasks "$spec")"
        merge_job="$(submit_merge "afterok:$array_job")"
        echo "resubmitted tasks $spec as $array_job, merge $merge_job"
    fi
    save
    ;;
batch)
    [ $# -ge 3 ] || { echo "usage: submit.sh batch LIST OUTDIR [render options…]" >&2; exit 2; }
    list="$(realpath "$2")"; out="$3"; shift 3
    mkdir -p "$out"; out="$(realpath "$out")"
    n="$(grep -c . "$list")"
    job="$(LUCENT="$lucent" LUCENT_LIST="$list" LUCENT_OUT="$out" LUCENT_ARGS="$*" \
        sbatch_job --array="0-$((n - 1))" --output="$out/batch-%a.log" --export=ALL "$here/batch-task.sbatch")"
    echo "submitted: $n scenes as array $job -> $out"
    ;;
*)
    sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
