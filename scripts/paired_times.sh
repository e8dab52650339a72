#!/usr/bin/env bash
# Two lucent binaries timed on one scene, paired: each round runs both back to back (in an
# order that alternates from round to round) and their ratio is taken there, so that a
# host whose speed drifts by 10-30 % between runs moves both sides of each ratio alike.
#
# usage: scripts/paired_times.sh SCENE.test BINARY_A BINARY_B
# env: ROUNDS (default 21), THREADS (default 1), REPS (default 3: `lucent bench scene
#      --reps`, whose render_s is the render phase's median over the reps)
#
# Prints the median of the per-round ratios A/B (above 1: B is faster) with its quartiles,
# and each binary's median and least render_s.
set -eu
. "$(dirname "$0")/paired_common.sh"
scene=${1:?usage: paired_times.sh SCENE.test BINARY_A BINARY_B}
a=${2:?usage: paired_times.sh SCENE.test BINARY_A BINARY_B}
b=${3:?usage: paired_times.sh SCENE.test BINARY_A BINARY_B}
rounds=${ROUNDS:-21}
threads=${THREADS:-1}
reps=${REPS:-3}

render_s() {
    local out
    out=$("$1" bench scene "$scene" --reps "$reps" --threads "$threads" 2>/dev/null | tail -1)
    case $out in
        *render_s=*) out=${out#*render_s=}; echo "${out%% *}" ;;
        *) echo "paired_times.sh: $1 gave no render_s for $scene" >&2; exit 1 ;;
    esac
}

pairs=$(mktemp)
trap 'rm -f "$pairs"' EXIT
paired_rounds "$rounds" render_s "$a" "$b" > "$pairs"
paired_summary "$pairs" "$scene" lower s
