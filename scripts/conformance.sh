#!/usr/bin/env bash
# Conformance: render the CSE167 course scenes and compare them with the course's
# reference images (../shared/corpus/README.md says which are official).
#
#   scene4-*, scene5, scene6, scene7 (PNG references): at most 300 of 307,200 pixels may
#     differ by more than 2/255 in any channel, and the mean absolute error must be < 0.05.
#   scene1-*, scene2-*, scene3 (lossy JPEG references): mean absolute error < 2.
#   The images are also byte-identical with 1 and 2 threads and with every --accel structure.
#
# The corpus is read where it is (never copied). Without it the check is skipped and says so.
# Usage: scripts/conformance.sh [CORPUS_DIR]   (default: ../shared/corpus beside the checkout)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
corpus=${1:-$root/../shared/corpus}
scenes=$corpus/cse167
if [ ! -d "$scenes" ]; then
    echo "conformance: SKIPPED: no course scenes at $scenes"
    exit 0
fi

(cd "$root" && cargo build --release --quiet)
bin=$root/target/release/lucent
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
passed=0
failed=0

check() { # name, extra lucent diff options...
    local name=$1; shift
    local ref=$scenes/ref/$name.png
    [ -f "$ref" ] || ref=$scenes/ref/$name.jpg
    local start end result
    start=$(date +%s.%N)
    if ! "$bin" render "$scenes/$name.test" -o "$out/$name.png" --threads 2 --quiet; then
        printf '%-16s FAIL (render failed)\n' "$name"; failed=$((failed + 1)); return
    fi
    end=$(date +%s.%N)
    if result=$("$bin" diff "$out/$name.png" "$ref" --threshold 2 "$@"); then
        printf '%-16s ok    %s  wall=%.3fs\n' "$name" "$result" "$(echo "$end - $start" | bc)"; passed=$((passed + 1))
    else
        printf '%-16s FAIL  %s  (limits: %s)\n' "$name" "$result" "$*"; failed=$((failed + 1))
    fi
}

same_bytes() { # name, lucent render options...
    local name=$1; shift
    "$bin" render "$scenes/$name.test" -o "$out/$name.alt.png" --quiet "$@"
    if cmp -s "$out/$name.png" "$out/$name.alt.png"; then
        printf '%-16s ok    byte-identical with %s\n' "$name" "$*"; passed=$((passed + 1))
    else
        printf '%-16s FAIL  differs with %s\n' "$name" "$*"; failed=$((failed + 1))
    fi
}

echo "conformance: course scenes from $scenes"
for s in scene4-ambient scene4-diffuse scene4-emission scene4-specular scene5 scene6 scene7; do
    check "$s" --max-pixels 300 --max-mae 0.05
done
for s in scene1-camera1 scene1-camera2 scene1-camera3 scene1-camera4 scene2-camera1 scene2-camera2 scene2-camera3 scene3; do
    check "$s" --max-mae 2
done
same_bytes scene7 --threads 1
same_bytes scene5 --threads 1
# Every acceleration structure must give the very same image.
for accel in kdtree grid octree list; do
    for s in scene4-specular scene5 scene6 scene7; do
        [ "$accel" = list ] && [ "$s" = scene7 ] && continue   # 100,000 triangles brute force: minutes
        same_bytes "$s" --accel "$accel"
    done
done

echo "conformance: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
