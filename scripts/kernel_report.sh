#!/usr/bin/env bash
# Every figure the ray kernel is judged by, in one run on this machine: single rays and
# packets against Embree 4.4, the build against Embree's and across threads, and memory per
# triangle, with the CPU model at the top (ratios hold only within one run on one machine).
#
# usage: scripts/kernel_report.sh [LUCENT_BINARY]     (default: target/release/lucent)
# env: WORK (default /tmp/lucent-kernel-report: the ray files, Embree's harness and the logs;
#      give the same WORK again to reuse them), ROUNDS (default 7: rounds of compare4.sh),
#      PACKET_ROUNDS (default 7: rounds of compare_packets.sh), BUILD_PAIRS (default 7: paired
#      runs of the 1- and 2-thread builds), ISA_ROUNDS (default 5: paired rounds of the AVX-512
#      paths against the AVX2 paths; 0 leaves that step out), AVX2_ROUNDS (default 3: rounds of
#      the run with both peers limited to AVX2; 0 leaves it out), BENCH (default
#      ../shared/bench), MESHES (default: both dragons of BENCH)
#
# Steps, each logged to WORK/*.txt and summed up in WORK/report.md:
#   1. `lscpu`'s model and AVX-512 flags;
#   2. ../shared/bench/compare4.sh (single rays against Embree 4's rtcIntersect1/rtcOccluded1,
#      CPU-time ratios; its build table: lucent's and Embree medium's single-threaded builds).
#      The ray files come from Embree 3 (Debian's libembree-dev), which this script installs
#      with apt-get when neither it nor earlier ray files in WORK are there;
#   3. scripts/compare_packets.sh (lucent's packets against Embree 4's 8- and 16-wide ones);
#   4. the BVH build of the largest mesh on 1 and 2 threads, paired (median of the per-pair
#      ratios), and bytes per triangle;
#   5. on a CPU with AVX-512 only: the same binary's AVX-512 paths (the default there) against
#      its AVX2 paths (`--isa avx2`, scripts/lucent_avx2.sh), paired with paired_rays.sh, on
#      every set, single rays and packets: whether AVX-512 pays on this machine;
#   6. on a CPU with AVX-512 only: both peers limited to AVX2, as on a CPU without AVX-512
#      (compare4.sh with Embree's `max_isa=avx2` and lucent's `--isa avx2`, then
#      compare_packets.sh with ISA=avx2, whose anchor is Embree's 8-wide packets). A CPU
#      without AVX-512 measures that in steps 2 and 3 already. (Its runs write the same
#      per-round files in WORK/<mesh>/ as steps 2 and 3: the raw rounds left are step 6's;
#      every step's table is in report.md.)
# Takes about an hour and a quarter on two cores with the defaults; use ROUNDS=1
# PACKET_ROUNDS=1 BUILD_PAIRS=1 ISA_ROUNDS=1 AVX2_ROUNDS=1 for a quick look.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
lucent=$(realpath "${1:-$here/../target/release/lucent}")
[ -x "$lucent" ] || { echo "kernel_report.sh: no lucent binary at $lucent (cargo build --release)" >&2; exit 2; }
bench=$(realpath "${BENCH:-$here/../../shared/bench}")
[ -d "$bench" ] || { echo "kernel_report.sh: no benchmark folder at $bench (set BENCH)" >&2; exit 2; }
WORK=${WORK:-/tmp/lucent-kernel-report}
ROUNDS=${ROUNDS:-7}; PACKET_ROUNDS=${PACKET_ROUNDS:-7}; BUILD_PAIRS=${BUILD_PAIRS:-7}; ISA_ROUNDS=${ISA_ROUNDS:-5}
AVX2_ROUNDS=${AVX2_ROUNDS:-3}
read -r -a meshes <<< "${MESHES:-$bench/dragon_100k.obj $bench/dragon_1m6.obj.gz}"
mkdir -p "$WORK"
report=$WORK/report.md

# Ray files: Embree 3 writes them unless an earlier run left them in WORK.
missing=0
for mesh in "${meshes[@]}"; do
  name=$(basename "$mesh" .gz); name=${name%.obj}
  [ -s "$WORK/$name/shadow.ref" ] || missing=1
done
if [ $missing = 1 ] && ! echo '#include <embree3/rtcore.h>' | g++ -x c++ -fsyntax-only - 2>/dev/null; then
  echo "# installing Embree 3 (libembree-dev) to write the ray files" >&2
  sudo=""; [ "$(id -u)" = 0 ] || sudo="sudo -n"
  { $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libembree-dev; } >&2 \
    || { echo "kernel_report.sh: cannot install libembree-dev; without it there are no ray files" >&2; exit 1; }
fi

{
  echo "# Ray kernel report, $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo
  echo "- CPU: $(lscpu | sed -n 's/^Model name: *//p' | head -1) ($(nproc) CPUs)"
  echo "- AVX-512 flags: $(grep -o -w 'avx512[a-z_0-9]*' /proc/cpuinfo | sort -u | tr '\n' ' ')"
  echo "- lucent: $lucent ($(cd "$here/.." && git rev-parse --short HEAD 2>/dev/null || echo '?'))"
  echo "- rounds: compare4 $ROUNDS, packets $PACKET_ROUNDS, build pairs $BUILD_PAIRS, ISA pairs $ISA_ROUNDS, both at AVX2 $AVX2_ROUNDS"
  echo
} > "$report"

echo "# 1/5 single rays: compare4.sh, ROUNDS=$ROUNDS" >&2
ROUNDS=$ROUNDS WORK=$WORK "$bench/compare4.sh" "$lucent" "${meshes[@]}" > "$WORK/compare4.txt" 2> "$WORK/compare4.err.txt" \
  || { echo "kernel_report.sh: compare4.sh failed, see $WORK/compare4.err.txt" >&2; exit 1; }
{ echo "## Single rays and builds (compare4.sh)"; echo; echo '```'; cat "$WORK/compare4.txt"; echo '```'; echo; } >> "$report"

echo "# 2/5 packets: compare_packets.sh, ROUNDS=$PACKET_ROUNDS" >&2
ROUNDS=$PACKET_ROUNDS "$here/compare_packets.sh" "$lucent" "$WORK" "${meshes[@]}" > "$WORK/packets.txt" 2> "$WORK/packets.err.txt" \
  || { echo "kernel_report.sh: compare_packets.sh failed, see $WORK/packets.err.txt" >&2; exit 1; }
{ echo "## Packets (compare_packets.sh)"; echo; echo '```'; cat "$WORK/packets.txt"; echo '```'; echo; } >> "$report"

# The build on 1 and 2 threads: a few rays only, so that the run is the build.
echo "# 3/5 build threads, $BUILD_PAIRS pairs" >&2
last=${meshes[${#meshes[@]}-1]}
name=$(basename "$last" .gz); name=${name%.obj}
obj=$last; [[ $last == *.gz ]] && obj=$WORK/$name.obj
head -c 3200 "$WORK/$name/primary.rays" > "$WORK/build.rays"
build_s() {
  local out
  out=$("$lucent" bench rays "$obj" "$WORK/build.rays" --reps 3 --threads 1 --build-threads "$1" 2>/dev/null | tail -1)
  echo "$out" >> "$WORK/build.txt"
  out=${out#*build_s=}; echo "${out%% *}"
}
: > "$WORK/build.txt"
pairs=$WORK/build.pairs; : > "$pairs"
for r in $(seq "$BUILD_PAIRS"); do
  if [ $((r % 2)) = 0 ]; then one=$(build_s 1); two=$(build_s 2); else two=$(build_s 2); one=$(build_s 1); fi
  echo "$one $two" >> "$pairs"
done
bytes=$(sed -n 's/.*bytes_per_tri=\([0-9.]*\).*/\1/p' "$WORK/build.txt" | head -1)
python3 - "$pairs" "$name" "$bytes" >> "$report" <<'PY'
import statistics, sys
path, name, bytes_per_tri = sys.argv[1:4]
rows = [tuple(map(float, l.split())) for l in open(path) if l.strip()]
ratios = sorted(a / b for a, b in rows)
n = len(ratios)
print(f"## Build threads ({name}, `bench rays --build-threads`, median of 3 builds per run)\n")
print(f"- 1 thread: median {statistics.median(r[0] for r in rows):.3f} s; "
      f"2 threads: median {statistics.median(r[1] for r in rows):.3f} s")
print(f"- 2 threads over 1, median of {n} paired ratios: **{statistics.median(ratios):.2f}×** "
      f"[{ratios[n // 4]:.2f}–{ratios[(3 * n) // 4]:.2f}] (target ≥ 1.7×)")
print(f"- memory: {bytes_per_tri} bytes per triangle (target ≤ 55)\n")
PY

# The AVX-512 paths against the AVX2 paths of the same binary (the ratio is AVX-512 / AVX2).
if [ "$ISA_ROUNDS" -gt 0 ] && grep -q -w avx512f /proc/cpuinfo; then
  echo "# 4/5 AVX-512 paths against AVX2 paths, ISA_ROUNDS=$ISA_ROUNDS" >&2
  {
    echo "## AVX-512 paths against AVX2 paths (\`paired_rays.sh\`, $ISA_ROUNDS rounds; above 1: AVX-512 is faster)"
    echo
    echo '```'
  } >> "$report"
  for mesh in "${meshes[@]}"; do
    name=$(basename "$mesh" .gz); name=${name%.obj}
    obj=$mesh; [[ $mesh == *.gz ]] && obj=$WORK/$name.obj
    for set in primary diffuse shadow; do
      for mode in single packets; do
        [ $mode = packets ] && [ $set = diffuse ] && continue   # no renderer path traces these in packets
        opts=(); [ $set = shadow ] && opts+=(--occluded); [ $mode = packets ] && opts+=(--packets)
        line=$(LUCENT=$lucent ROUNDS=$ISA_ROUNDS "$here/paired_rays.sh" "$obj" "$WORK/$name/$set.rays" \
                 "$here/lucent_avx2.sh" "$lucent" "${opts[@]}" 2>> "$WORK/isa.err.txt" | head -1) \
          || { echo "kernel_report.sh: paired_rays.sh failed, see $WORK/isa.err.txt" >&2; exit 1; }
        echo "$name $set $mode: ${line#*: }" >> "$report"
      done
    done
  done
  echo '```' >> "$report"
fi

# Both peers limited to AVX2 (the answers and ray files are the same; Embree is told by its
# device config, lucent by --isa avx2 through its wrapper).
if [ "$AVX2_ROUNDS" -gt 0 ] && grep -q -w avx512f /proc/cpuinfo; then
  echo "# 5/5 both peers limited to AVX2, AVX2_ROUNDS=$AVX2_ROUNDS" >&2
  LUCENT=$lucent EB_CONFIG=max_isa=avx2 EMBREE3=0 ROUNDS=$AVX2_ROUNDS WORK=$WORK "$bench/compare4.sh" \
    "$here/lucent_avx2.sh" "${meshes[@]}" > "$WORK/avx2.txt" 2> "$WORK/avx2.err.txt" \
    || { echo "kernel_report.sh: compare4.sh at AVX2 failed, see $WORK/avx2.err.txt" >&2; exit 1; }
  ISA=avx2 ROUNDS=$AVX2_ROUNDS "$here/compare_packets.sh" "$lucent" "$WORK" "${meshes[@]}" \
    > "$WORK/avx2_packets.txt" 2> "$WORK/avx2_packets.err.txt" \
    || { echo "kernel_report.sh: compare_packets.sh at AVX2 failed, see $WORK/avx2_packets.err.txt" >&2; exit 1; }
  {
    echo "## Both peers limited to AVX2, as on a CPU without AVX-512 ($AVX2_ROUNDS rounds)"
    echo
    echo '```'
    cat "$WORK/avx2.txt"
    echo
    cat "$WORK/avx2_packets.txt"
    echo '```'
    echo
  } >> "$report"
fi
cat "$report"
echo "# report: $report" >&2
