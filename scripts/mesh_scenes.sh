#!/usr/bin/env bash
# Meshes and instances at scale (issue: every kind of geometry), on the course's bench
# meshes in ../shared/bench (read where they are, never copied):
#   1. dragon_1m6 (1.6 M triangles, decompressed to a temporary folder) loaded with
#      `mesh`, built and rendered at 640x480 with 2 threads;
#   2. one dragon_100k against 1,000 instances of it (objectbegin/instance).
# Prints wall time and peak memory (GNU time's maximum resident set size) of each run.
# Usage: scripts/mesh_scenes.sh [path/to/lucent]   (default target/release/lucent)
set -euo pipefail
cd "$(dirname "$0")/.."
LUCENT=${1:-target/release/lucent}
BENCH=$(realpath ../shared/bench 2>/dev/null || true)
if [ -z "$BENCH" ] || [ ! -f "$BENCH/dragon_100k.obj" ]; then
    echo "mesh_scenes: ../shared/bench not found: skipped"
    exit 0
fi
[ -x "$LUCENT" ] || cargo build --release --quiet
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
gzip -dc "$BENCH/dragon_1m6.obj.gz" > "$WORK/dragon_1m6.obj"

header() {
    printf 'size 640 480\ncamera %s\nambient 0.05 0.05 0.05\ndirectional 1 1 1 0.7 0.7 0.7\n' "$1"
    printf 'point -10 10 10 0.5 0.5 0.5\ndiffuse 0.7 0.6 0.4\nspecular 0.2 0.2 0.2\nshininess 30\n'
}
{ header "0 5 22 0 4.5 0 0 1 0 40"; echo "mesh $WORK/dragon_1m6.obj"; } > "$WORK/big.test"
{ header "0 120 190 0 0 0 0 1 0 45"; echo "mesh $BENCH/dragon_100k.obj"; } > "$WORK/one.test"
{
    header "0 120 190 0 0 0 0 1 0 45"
    printf 'objectbegin dragon\nmesh %s\nobjectend\n' "$BENCH/dragon_100k.obj"
    for i in $(seq 0 9); do for j in $(seq 0 9); do for k in $(seq 0 9); do
        printf 'pushTransform\ntranslate %d %d %d\nrotate 0 1 0 %d\ninstance dragon\npopTransform\n' \
            $(( (i - 5) * 16 )) $(( (j - 5) * 16 )) $(( (k - 5) * 16 )) $(( (i * 37 + j * 101 + k * 53) % 360 ))
    done; done; done
} > "$WORK/many.test"

run() {
    local name=$1
    /usr/bin/time -f "%e %M" -o "$WORK/time" "$LUCENT" render "$WORK/$name.test" -o "$WORK/$name.png" --threads 2 --stats 2>"$WORK/log" ||
        { cat "$WORK/log"; exit 1; }
    read -r wall kb < "$WORK/time"
    echo "$name: wall ${wall} s, peak memory $((kb / 1024)) MB"
    grep -E 'primitives|parse' "$WORK/log" | sed 's/^/    /'
}
run big
run one
run many
