#!/usr/bin/env bash
# Renders the sixteen CSE168 course scenes (homeworks 2-4) with lucent into docs/cse168/,
# for the gallery (docs/gallery.md). The scenes are read where they are, in the course
# corpus (never copied); the hw2 pictures come from the scene files the course's reference
# images were made from (corpus/cse168/ref/hw2/). Takes about 3 minutes on 2 cores.
#
# Usage: scripts/render_course_gallery.sh [CORPUS_DIR]   (default: ../shared/corpus beside the checkout)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
corpus=${1:-$root/../shared/corpus}
mc=$corpus/cse168
if [ ! -d "$mc" ]; then
    echo "render_course_gallery: no CSE168 scenes at $mc" >&2
    exit 2
fi
(cd "$root" && cargo build --release --quiet)
bin=$root/target/release/lucent
out=$root/docs/cse168
mkdir -p "$out"
for scene in ref/hw2/analytic ref/hw2/direct9 ref/hw2/direct3x3 ref/hw2/sphere ref/hw2/cornell ref/hw2/dragon \
             hw3/cornellSimple hw3/cornellNEE hw3/cornellRR hw3/dragon \
             hw4/cornellCosine hw4/cornellBRDF hw4/cornellMIS hw4/ggx hw4/mis hw4/dragon; do
    hw=$(basename "$(dirname "$scene")")
    name=$hw-$(basename "$scene")
    start=$(date +%s.%N)
    "$bin" render "$mc/$scene.test" -o "$out/$name.png" --quiet
    printf '%-22s %6.1f s\n' "$name" "$(echo "$(date +%s.%N) - $start" | bc)"
done
