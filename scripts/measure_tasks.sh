#!/usr/bin/env bash
# Measures a plan (`lucent plan --measure`): renders every task of it one after the
# other on one thread, prints the time of each (CPU seconds), the spread, the merge time,
# and checks that the merged PNG and EXR are byte-identical to the render made in one go.
# Usage: scripts/measure_tasks.sh SCENE N [--by auto|tiles|samples] [render options…]
# The figures of docs/scale-out.md come from this script.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
scene="$(realpath "$1")"; n="$2"; shift 2
lucent="${LUCENT:-$here/target/release/lucent}"
[ -x /usr/bin/time ] || { echo "measure_tasks: needs GNU time (apt-get install time)" >&2; exit 1; }
[ -x "$lucent" ] || (cd "$here" && cargo build --release -q)
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
cd "$work"
lscpu | sed -n 's/^Model name: *//p' | head -n 1 | sed 's/^/cpu: /'
# The plan, its bands balanced by the measured time of a probe; every task reads it.
"$lucent" plan "$scene" --tasks "$n" --measure --json plan.json -q "$@" | head -n 1
cpu() { # user+system seconds of a command
    /usr/bin/time -f "%U %S" -o t.txt "$@" >/dev/null
    awk '{printf "%.2f", $1 + $2}' t.txt
}
times=()
for ((i = 0; i < n; i++)); do
    t="$(cpu "$lucent" render "$scene" --task "$i/$n" --plan plan.json --state "task$i.lstate" -o "task$i.png" -q --threads 1 "$@")"
    times+=("$t")
    echo "task $i: $t s"
done
printf '%s\n' "${times[@]}" | awk '{s += $1; if (NR == 1 || $1 < lo) lo = $1; if ($1 > hi) hi = $1}
    END {printf "tasks: mean %.2f s, min %.2f, max %.2f, max/min %.3f, (max-min)/max %.1f%%\n", s/NR, lo, hi, hi/lo, 100*(hi-lo)/hi}'
t="$(cpu "$lucent" merge task*.lstate -o merged.png)"
echo "merge to PNG: $t s ($(du -ch task*.lstate | tail -n 1 | cut -f1) of states)"
"$lucent" merge task*.lstate -o merged.exr
t="$(cpu "$lucent" render "$scene" -o one.png -q --threads 1 "$@")"
echo "one go, one thread: $t s"
"$lucent" render "$scene" -o one.exr -q "$@"
cmp -s one.png merged.png && cmp -s one.exr merged.exr && echo "merged PNG and EXR are byte-identical to the one-go render" || { echo "MERGED IMAGE DIFFERS"; exit 1; }
