#!/usr/bin/env bash
# The acceleration-structure benchmark behind docs/performance.md.
#
#   scripts/bench_accel.sh [MESH.obj|MESH.obj.gz ...]
#       default: ../shared/bench/dragon_100k.obj ../shared/bench/dragon_1m6.obj.gz
#
# 1. Runs ../shared/bench/compare.sh: Embree 3 and `lucent bench rays --accel bvh` side by
#    side on the same files (primary, diffuse and shadow rays written by the Embree harness),
#    one thread, and prints the ratios and how many answers differ from Embree's.
# 2. On the same ray files, one thread: every other structure (kdtree, grid, octree; list on
#    2,000 rays spread over each set only: brute force on the whole set takes hours), and
#    the BVH with two threads. Prints one line per run (build_s, bytes_per_tri, Mrays/s).
#
# Needs g++ and Debian's libembree-dev (installed here with apt-get when missing and root).
# Env: REPS (default 5), WORK (default: a temporary directory, kept for inspection).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bench=$root/../shared/bench
if [ ! -d "$bench" ]; then
    echo "bench_accel: SKIPPED: no benchmark material at $bench"; exit 0
fi
if [ ! -f /usr/include/embree3/rtcore.h ] && [ "$(id -u)" = 0 ]; then
    apt-get update -qq && apt-get install -y -qq g++ libembree-dev >/dev/null
fi
meshes=("$@"); [ ${#meshes[@]} -gt 0 ] || meshes=("$bench/dragon_100k.obj" "$bench/dragon_1m6.obj.gz")
export REPS=${REPS:-5}
export WORK=${WORK:-$(mktemp -d)}
mkdir -p "$WORK"
(cd "$root" && cargo build --release --quiet)
bin=$root/target/release/lucent

echo "== Embree 3 vs lucent bvh (1 thread) =="
bash "$bench/compare.sh" "$bin" "${meshes[@]}"

echo "== every structure (lucent bench rays; list on 2,000 rays spread over each set) =="
for mesh in "${meshes[@]}"; do
    name=$(basename "$mesh" .gz); name=${name%.obj}
    obj=$mesh; [[ $mesh == *.gz ]] && obj=$WORK/$name.obj
    for set in primary diffuse shadow; do
        occ=(); [ $set = shadow ] && occ=(--occluded)
        rays=$WORK/$name/$set.rays
        # 2,000 rays spread evenly over the set (the first ones would all be sky).
        python3 -c "import numpy as np, sys; r = np.fromfile(sys.argv[1], '<f4').reshape(-1, 8); r[::max(1, len(r) // 2000)][:2000].tofile(sys.argv[2])" \
            "$rays" "$WORK/$name/$set.2000.rays"
        for accel in bvh kdtree grid octree list; do
            r=$rays; reps=$REPS
            if [ $accel = list ]; then r=$WORK/$name/$set.2000.rays; reps=1; fi
            printf '%-12s %-8s %-7s 1 thread   %s\n' "$name" "$set" "$accel" \
                "$("$bin" bench rays "$obj" "$r" --accel $accel --threads 1 --reps $reps "${occ[@]}" | tail -1)"
        done
        printf '%-12s %-8s %-7s 2 threads  %s\n' "$name" "$set" bvh \
            "$("$bin" bench rays "$obj" "$rays" --accel bvh --threads 2 --reps "$REPS" "${occ[@]}" | tail -1)"
    done
done
echo "(work files in $WORK)"
