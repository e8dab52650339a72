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
for r in $(seq "$rounds"); do
    if [ $((r % 2)) = 0 ]; then
        ta=$(render_s "$a"); tb=$(render_s "$b")
    else
        tb=$(render_s "$b"); ta=$(render_s "$a")
    fi
    echo "$ta $tb" >> "$pairs"
done

python3 - "$pairs" "$scene" <<'PY'
import statistics, sys
rows = [tuple(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
ratios = sorted(a / b for a, b in rows)
n = len(ratios)
q1, q3 = ratios[n // 4], ratios[(3 * n) // 4]
a = [r[0] for r in rows]
b = [r[1] for r in rows]
print(f"{sys.argv[2]}: A/B median {statistics.median(ratios):.3f} [quartiles {q1:.3f}-{q3:.3f}], {n} rounds")
print(f"  A median {statistics.median(a):.4f} s, least {min(a):.4f} s")
print(f"  B median {statistics.median(b):.4f} s, least {min(b):.4f} s")
PY
