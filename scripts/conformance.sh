#!/usr/bin/env bash
# Conformance: render the CSE167 course scenes and compare them with the course's
# reference images (../shared/corpus/README.md says which are official).
#
#   scene4-*, scene5, scene6, scene7 (PNG references): at most 300 of 307,200 pixels may
#     differ by more than 2/255 in any channel (scene5: 10), and the mean absolute error must be < 0.05.
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
    # scene5 is held to what lucent reaches since rays leave surfaces past their rounding
    # error (1 pixel; the best independent implementation has 10).
    limit=300; [ "$s" = scene5 ] && limit=10
    check "$s" --max-pixels "$limit" --max-mae 0.05
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

# CSE168: the Monte Carlo integrators.
mc=$corpus/cse168
if [ -d "$mc" ]; then
    echo "conformance: CSE168 scenes from $mc"
    # analyticdirect is deterministic: compared pixel by pixel. 10 pixels are one step off (an
    # independent reimplementation of the formula gets 12: SCENE_FORMAT.md, REF-IMG); at most 20 may be.
    "$bin" render "$mc/ref/hw2/analytic.test" -o "$out/analytic.png" --quiet
    if result=$("$bin" diff "$out/analytic.png" "$mc/ref/hw2/analytic.png" --threshold 0 --max-pixels 20); then
        printf '%-16s ok    %s\n' analytic "$result"; passed=$((passed + 1))
    else
        printf '%-16s FAIL  %s\n' analytic "$result"; failed=$((failed + 1))
    fi
    # direct: statistically, with the thresholds statcmp.py calibrated on independent renders.
    for s in direct9 direct3x3 sphere cornell dragon; do
        "$bin" render "$mc/ref/hw2/$s.test" -o "$out/$s.png" --quiet
        if result=$(python3 "$root/../shared/tools/statcmp.py" "$out/$s.png" "$mc/ref/hw2/$s.png" --preset "hw2_$s" 2>&1 | tail -1) && [[ $result == PASS* ]]; then
            printf '%-16s ok    %s\n' "$s" "$result"; passed=$((passed + 1))
        else
            printf '%-16s FAIL  %s\n' "$s" "$result"; failed=$((failed + 1))
        fi
    done
    # Every hw3 and hw4 scene renders; variants of one scene agree in linear radiance.
    for s in hw3/cornellSimple hw3/cornellNEE hw3/cornellRR hw3/dragon hw4/cornellCosine hw4/cornellBRDF hw4/cornellMIS hw4/ggx hw4/mis hw4/dragon; do
        n=$(basename "$s")
        if "$bin" render "$mc/$s.test" -o "$out/$n.exr" --quiet 2>"$out/$n.log"; then
            printf '%-16s ok    renders\n' "$s"; passed=$((passed + 1))
        else
            printf '%-16s FAIL  %s\n' "$s" "$(tail -1 "$out/$n.log")"; failed=$((failed + 1))
        fi
    done
    agree() { # a b [spp]: two estimators of one scene
        local a=$1 b=$2 spp=${3:-}
        if [ -n "$spp" ]; then
            "$bin" render "$mc/$a.test" -o "$out/a.exr" --quiet --spp "$spp"
            "$bin" render "$mc/$b.test" -o "$out/b.exr" --quiet --spp "$spp"
        else
            cp "$out/$(basename "$a").exr" "$out/a.exr"; cp "$out/$(basename "$b").exr" "$out/b.exr"
        fi
        if result=$("$bin" diff --noise "$out/a.exr" "$out/b.exr"); then
            printf '%-16s ok    %s vs %s: %s\n' agree "$a" "$b" "$result"; passed=$((passed + 1))
        else
            printf '%-16s FAIL  %s vs %s: %s\n' agree "$a" "$b" "$result"; failed=$((failed + 1))
        fi
    }
    agree hw3/cornellSimple hw3/cornellNEE
    # The glossy sphere (shininess 1000) makes rare bright samples whose spread 64
    # samples underestimate: these compare at 256.
    agree hw4/cornellMIS hw4/cornellBRDF 256
    # Russian roulette (unbounded depth) against the same scene cut at 30 scattering events
    # instead of 5: what the 31st event on adds is far below the noise.
    sed 's/^maxdepth .*/maxdepth 30/' "$mc/hw3/cornellNEE.test" > "$out/cornellNEE30.test"
    "$bin" render "$out/cornellNEE30.test" -o "$out/a.exr" --quiet
    cp "$out/cornellRR.exr" "$out/b.exr"
    if result=$("$bin" diff --noise "$out/a.exr" "$out/b.exr"); then
        printf '%-16s ok    hw3/cornellNEE at maxdepth 30 vs hw3/cornellRR: %s\n' agree "$result"; passed=$((passed + 1))
    else
        printf '%-16s FAIL  hw3/cornellNEE at maxdepth 30 vs hw3/cornellRR: %s\n' agree "$result"; failed=$((failed + 1))
    fi
else
    echo "conformance: CSE168 SKIPPED: no scenes at $mc"
fi

echo "conformance: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
