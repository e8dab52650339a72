#!/usr/bin/env bash
# Coherent rays side by side: Embree 4.4's packet queries (rtcIntersect8/16, rtcOccluded8/16)
# against lucent's packets (`lucent bench rays --packets`: 16 rays with AVX-512, 8 with AVX2), on
# the same ray files, interleaved, as Mrays per CPU-second of the tracing thread(s).
#
# usage: scripts/compare_packets.sh LUCENT_BINARY WORK [MESH.obj ...]   (default: dragon_100k.obj)
#   WORK is the work directory of an earlier run of ../shared/bench/compare4.sh with the same
#   meshes: this script reuses its Embree 4 harness (embree4_bench), its CPU-time wrapper
#   (lucent_cpu.py) and its ray files (WORK/<mesh>/{primary,diffuse,shadow}.{rays,ref}).
# env: ROUNDS (default 3: runs of each peer, interleaved, order alternating), REPS (default 7),
#      THREADS (default 1), BENCH (default ../shared/bench, for the default mesh),
#      ISA=avx2 (both peers limited to AVX2, as on a CPU without AVX-512: lucent with
#      `--isa avx2`, Embree with `max_isa=avx2` in its device config; then its 16-wide
#      queries run as 8-wide ones)
#
# Prints, per mesh and ray set, the median over rounds [min-max] of Embree 4's 8- and 16-wide
# packets and of lucent's packets, the ratio lucent / (Embree's faster packet width), and how
# many of lucent's answers differ from the Embree 3 reference in WORK (compare4.sh's rule).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
lucent=${1:?usage: compare_packets.sh LUCENT_BINARY WORK [MESH ...]}
work=${2:?usage: compare_packets.sh LUCENT_BINARY WORK [MESH ...]}
shift 2
bench=${BENCH:-$here/../../shared/bench}
meshes=("$@"); [ ${#meshes[@]} -gt 0 ] || meshes=("$bench/dragon_100k.obj")
ROUNDS=${ROUNDS:-3}; REPS=${REPS:-7}; THREADS=${THREADS:-1}
isa_args=(); eb_config=${EB_CONFIG:-}
case ${ISA:-} in
  "") ;;
  avx2) isa_args=(--isa avx2); eb_config="${eb_config:+$eb_config,}max_isa=avx2" ;;
  *) echo "compare_packets.sh: ISA=$ISA: only avx2 (or nothing: each peer's best)" >&2; exit 2 ;;
esac
for f in "$work/embree4_bench" "$work/lucent_cpu.py"; do
  [ -e "$f" ] || { echo "compare_packets.sh: $f is missing: run ../shared/bench/compare4.sh with WORK=$work first" >&2; exit 1; }
done
names=()
for mesh in "${meshes[@]}"; do
  name=$(basename "$mesh" .gz); name=${name%.obj}; names+=("$name")
  d="$work/$name"; obj=$mesh
  [[ $mesh == *.gz ]] && obj="$work/$name.obj"
  for set in primary shadow; do
    [ -s "$d/$set.rays" ] || { echo "compare_packets.sh: no $d/$set.rays: run compare4.sh on $mesh with WORK=$work first" >&2; exit 1; }
  done
  rm -f "$d"/packets.*.txt "$d"/packets.embree4.*.tsv
  for r in $(seq 1 "$ROUNDS"); do
    if (( r % 2 )); then order="e4 lucent"; else order="lucent e4"; fi
    for p in $order; do
      case $p in
        e4) env EB_CONFIG="$eb_config" EB_QUALS=medium EB_TRACE_QUALS=medium EB_MODES=8,16 EB_THREADS="$THREADS" EB_BUILD_THREADS=1 \
              "$work/embree4_bench" "$obj" "$d" "$REPS" > "$d/packets.embree4.r$r.tsv" 2>&1 ;;
        lucent)
          for set in primary diffuse shadow; do
            if [ $set = shadow ]; then occ=--occluded; else occ=; fi
            python3 "$work/lucent_cpu.py" "$lucent" bench rays "$obj" "$d/$set.rays" --reps "$REPS" --threads "$THREADS" \
              --packets $occ ${isa_args[@]+"${isa_args[@]}"} --hits "$d/$set.lucent_packets" > "$d/packets.lucent.$set.r$r.txt" 2>&1 \
              || echo "compare_packets.sh: lucent failed on $name/$set, see $d/packets.lucent.$set.r$r.txt" >&2
          done ;;
      esac
    done
  done
done

python3 - "$work" "$ROUNDS" "$THREADS" "${names[@]}" <<'PY'
import os, re, sys, statistics as st
import numpy as np
work, rounds, threads, names = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4:]
kv = lambda t: dict(re.findall(r"(\w+)=([^\s]+)", t))
dt = np.dtype([("t", "<f4"), ("prim", "<u4")])

def embree(path, query, s):
    if not os.path.exists(path): return None
    for line in open(path):
        f = line.rstrip("\n").split("\t")
        if len(f) >= 10 and f[0] == "RESULT" and f[1] == f"embree4-medium-{query}" and f[3] == s and f[4] == threads:
            c = kv(f[9]).get("cpu_rate", "").replace("Mrays/cpu-s", "")
            return float(c) if c else None
    return None

def lucent(path):
    if not os.path.exists(path): return None
    m = kv(open(path).read())
    return float(m["cpu_rate"]) if "cpu_rate" in m else None

def cell(v):
    v = [x for x in v if x is not None]
    if not v: return "-"
    return f"{st.median(v):.2f}" + (f" [{min(v):.2f}-{max(v):.2f}]" if len(v) > 1 else "")

def mismatches(ref, got, occl):
    if not (os.path.exists(ref) and os.path.exists(got)): return "?"
    a, b = np.fromfile(ref, dtype=dt), np.fromfile(got, dtype=dt)
    if len(a) != len(b): return "count"
    if occl: return str(int(((a["t"] == 0) != (b["t"] == 0)).sum()))
    ha, hb = a["prim"] != 0xFFFFFFFF, b["prim"] != 0xFFFFFFFF
    return str(int(((ha != hb) | (ha & hb & (a["prim"] != b["prim"]))).sum()))

print(f"{'mesh':<12} {'rays':<8} {'embree4 x8':>20} {'embree4 x16':>20} {'lucent packets':>20} {'ratio':>20} {'mismatches':>10}")
for name in names:
    d = os.path.join(work, name)
    for s in ("primary", "diffuse", "shadow"):
        q = "rtcOccluded%d" if s == "shadow" else "rtcIntersect%d"
        e8 = [embree(os.path.join(d, f"packets.embree4.r{r}.tsv"), q % 8, s) for r in range(1, rounds + 1)]
        e16 = [embree(os.path.join(d, f"packets.embree4.r{r}.tsv"), q % 16, s) for r in range(1, rounds + 1)]
        lu = [lucent(os.path.join(d, f"packets.lucent.{s}.r{r}.txt")) for r in range(1, rounds + 1)]
        # Paired within a round, against the faster of Embree's two widths.
        ratio = [l / max(a or 0, b or 0) for l, a, b in zip(lu, e8, e16) if l and (a or b)]
        mm = mismatches(os.path.join(d, f"{s}.ref"), os.path.join(d, f"{s}.lucent_packets"), s == "shadow")
        print(f"{name:<12} {s:<8} {cell(e8):>20} {cell(e16):>20} {cell(lu):>20} {cell(ratio):>20} {mm:>10}")
print(f"\n(Mrays per CPU-second, {threads} thread(s), median of {rounds} interleaved rounds [min-max]; "
      f"ratio = lucent / the faster Embree packet width, paired by round; mismatches against the Embree 3 reference)")
PY
[ -z "${ISA:-}" ] || echo "Both peers limited to ${ISA}."
echo "CPU: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1); $(grep -o 'avx512[a-z_0-9]*' /proc/cpuinfo 2>/dev/null | sort -u | tr '\n' ' ')"
