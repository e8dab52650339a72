#!/usr/bin/env bash
# Two lucent binaries on one ray file, paired: each round runs `lucent bench rays` with both,
# back to back, in an order that alternates from round to round, and takes their ratio there,
# so that a host whose speed drifts between runs moves both sides of each ratio alike (the
# kernel counterpart of paired_times.sh).
#
# usage: scripts/paired_rays.sh MESH.obj RAYS BINARY_A BINARY_B [bench rays options ...]
#   e.g. scripts/paired_rays.sh dragon_100k.obj work/dragon_100k/shadow.rays old new --occluded
#        (the options go to both binaries: --packets, --occluded, --isa ...)
# env: ROUNDS (default 10; an even count runs each binary first equally often), REPS (default 7:
#      `bench rays --reps`, whose rate is the median over the passes), THREADS (default 1)
#
# Prints the median of the per-round ratios B/A of Mrays/s (above 1: B is faster) with its
# quartiles, and each binary's median and highest rate.
set -eu
. "$(dirname "$0")/paired_common.sh"
usage="usage: paired_rays.sh MESH.obj RAYS BINARY_A BINARY_B [bench rays options ...]"
mesh=${1:?$usage}
rays=${2:?$usage}
a=${3:?$usage}
b=${4:?$usage}
shift 4
rounds=${ROUNDS:-10}
reps=${REPS:-7}
threads=${THREADS:-1}

rate() {
    local out
    out=$("$1" bench rays "$mesh" "$rays" --reps "$reps" --threads "$threads" "${@:2}" 2>/dev/null | tail -1)
    case $out in
        *mrays_per_s=*) out=${out#*mrays_per_s=}; echo "${out%% *}" ;;
        *) echo "paired_rays.sh: $1 gave no mrays_per_s for $rays" >&2; exit 1 ;;
    esac
}

options=("$@")
measure() { rate "$1" "${options[@]}"; }

pairs=$(mktemp)
trap 'rm -f "$pairs"' EXIT
paired_rounds "$rounds" measure "$a" "$b" > "$pairs"
paired_summary "$pairs" "$rays" higher Mrays/s
