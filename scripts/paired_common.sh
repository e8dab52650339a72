# Sourced by paired_times.sh and paired_rays.sh: the rounds of a paired comparison and
# their summary, shared so that both scripts pair and report alike.

# paired_rounds ROUNDS MEASURE A B: prints one line "value_A value_B" per round, each round
# running `MEASURE A` and `MEASURE B` back to back, the one that goes first alternating
# from round to round (so drift favours neither). MEASURE prints one number or exits.
paired_rounds() {
    local rounds=$1 measure=$2 a=$3 b=$4 r va vb
    for r in $(seq "$rounds"); do
        if [ $((r % 2)) = 0 ]; then
            va=$("$measure" "$a"); vb=$("$measure" "$b")
        else
            vb=$("$measure" "$b"); va=$("$measure" "$a")
        fi
        echo "$va $vb"
    done
}

# paired_summary PAIRS LABEL BETTER UNIT: the median of the per-round ratios (above 1: B is
# better; BETTER is `lower` for times, `higher` for rates) with its quartiles, then each
# side's median and best value (least time, most rate) in UNIT.
paired_summary() {
    python3 - "$@" <<'PY'
import statistics, sys
pairs, label, better, unit = sys.argv[1:5]
rows = [tuple(map(float, l.split())) for l in open(pairs) if l.strip()]
lower = better == "lower"
ratios = sorted(a / b if lower else b / a for a, b in rows)
n = len(ratios)
q1, q3 = ratios[n // 4], ratios[(3 * n) // 4]
name = "A/B" if lower else "B/A"
print(f"{label}: {name} median {statistics.median(ratios):.3f} [quartiles {q1:.3f}-{q3:.3f}], {n} rounds")
best, word = (min, "least") if lower else (max, "most")
for side, i in (("A", 0), ("B", 1)):
    values = [r[i] for r in rows]
    print(f"  {side} median {statistics.median(values):.4f} {unit}, {word} {best(values):.4f} {unit}")
PY
}
