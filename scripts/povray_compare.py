#!/usr/bin/env python3
"""lucent beside POV-Ray 3.7 on the same Whitted scenes: CPU time of the whole process and
of the render phase, interleaved rounds, and how far apart the two pictures are.

usage: scripts/povray_compare.py LUCENT_BINARY [SCENE.test ...]

Without scenes it takes the CSE167 scenes 4 (specular), 5, 6 and 7 from
$CORPUS/cse167/ (default: ../shared/corpus beside the repository) and stops with a
message if they are not there. Each scene is written as a POV-Ray scene by
scripts/to_povray.py (which says how the shading is matched); scenes with commands beyond
the CSE167 ray tracer's are refused.

Environment: ROUNDS (default 5), THREADS (default 1: lucent --threads N, POV-Ray +WTN),
SCALE (default 1: each side of the picture times this, in both programs; the course
scenes take a tenth of a second at 640 x 480, so SCALE=3 gives timings that a noisy host
moves less), WORK (default: a new temporary folder; the .pov files, images and logs stay there).
POV-Ray comes from Debian (`apt-get install -y povray`, run here when `povray` is
missing).

Per scene and round both programs render in fresh processes, in an order that alternates
from round to round. CPU seconds are the process's user + system time (os.wait4); the
render phase is the wall time of tracing the picture that each program reports (lucent's
`render` time from --stats, POV-Ray's "Trace Time"), which with one thread is its CPU
time too. Each measurement is also written to WORK/rounds.tsv. Ratios are POV-Ray / lucent per round
(above 1: lucent is faster), their median over rounds [min-max]. The pictures are compared
with `lucent diff` (pixels with a channel more than 2/255 apart, mean absolute error).
"""

import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SCENES = ["scene4-specular", "scene5", "scene6", "scene7"]


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def timed(argv, cwd=None):
    """Runs argv; returns (CPU seconds of the process, its stdout + stderr)."""
    with tempfile.TemporaryFile() as log:
        proc = subprocess.Popen(argv, cwd=cwd, stdout=log, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        log.seek(0)
        text = log.read().decode("utf-8", "replace")
    if proc.returncode != 0:
        raise RuntimeError("%s exited with %d:\n%s" % (argv[0], proc.returncode, text[-2000:]))
    return usage.ru_utime + usage.ru_stime, text


def ensure_povray():
    if shutil.which("povray"):
        return
    print("povray_compare.py: povray is missing; running apt-get install -y povray", file=sys.stderr)
    if subprocess.run(["apt-get", "install", "-y", "povray"], stdout=subprocess.DEVNULL).returncode != 0 \
            or not shutil.which("povray"):
        sys.exit("povray_compare.py: could not install povray (apt-get install -y povray failed)")


def run_lucent(lucent, scene, out, size, threads):
    cpu, text = timed([lucent, "render", scene, "-o", out, "--size", str(size[0]), str(size[1]),
                       "--threads", str(threads), "--stats", "-q"])
    m = re.search(r"render ([0-9.]+) s on .*?, ([0-9.]+) rays per sample", text)
    if not m:
        raise RuntimeError("no --stats line from lucent:\n" + text)
    return cpu, float(m.group(1)), float(m.group(2)) * size[0] * size[1]


def run_povray(pov, out, size, threads, work):
    argv = ["povray", "+I" + pov, "+O" + out, "+W%d" % size[0], "+H%d" % size[1], "-D", "-P", "-A",
            "+WT%d" % threads, "+FN", "File_Gamma=1.0", "-GR"]
    cpu, text = timed(argv, cwd=work)
    m = re.search(r"Trace Time:.*?\(([0-9.]+) seconds\)", text, re.S)
    rays = re.search(r"Rays:\s+(\d+)", text)
    shadow = re.search(r"Shadow Ray Tests:\s+(\d+)", text)
    if not (m and rays):
        raise RuntimeError("no statistics from povray:\n" + text[-3000:])
    # (No shadow ray line when the scene has no light.)
    return cpu, float(m.group(1)), int(rays.group(1)) + (int(shadow.group(1)) if shadow else 0)


def summary(values):
    return statistics.median(values), min(values), max(values)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    lucent = os.path.abspath(sys.argv[1])
    scenes = [os.path.abspath(s) for s in sys.argv[2:]]
    if not scenes:
        corpus = os.environ.get("CORPUS", os.path.join(HERE, "..", "..", "shared", "corpus"))
        scenes = [os.path.abspath(os.path.join(corpus, "cse167", s + ".test")) for s in DEFAULT_SCENES]
        missing = [s for s in scenes if not os.path.exists(s)]
        if missing:
            sys.exit("povray_compare.py: the course scenes are not there (%s); set CORPUS or name scenes" % missing[0])
    rounds = int(os.environ.get("ROUNDS", "5"))
    threads = int(os.environ.get("THREADS", "1"))
    scale = int(os.environ.get("SCALE", "1"))
    work = os.path.abspath(os.environ.get("WORK") or tempfile.mkdtemp(prefix="povray_compare."))
    os.makedirs(work, exist_ok=True)
    ensure_povray()
    version = subprocess.run(["povray", "--version"], capture_output=True, text=True).stderr
    version = next((l.strip() for l in version.splitlines() if l.startswith("POV-Ray")), "POV-Ray")
    print("CPU: %s; %s; %d round(s), %d thread(s), pictures %d times the scene's size; work files in %s"
          % (cpu_model(), version, rounds, threads, scale, work))
    print()
    print("| scene | rays, lucent / POV-Ray | process CPU-s, lucent / POV-Ray (medians) | POV-Ray / lucent, process | "
          "render phase, lucent / POV-Ray (wall s) | POV-Ray / lucent, render | pixels > 2/255 apart, MAE |")
    print("|---|---|---|---|---|---|---|")
    failed = False
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        pov = os.path.join(work, name + ".pov")
        conv = subprocess.run([sys.executable, os.path.join(HERE, "to_povray.py"), scene, pov],
                              capture_output=True, text=True)
        if conv.returncode != 0:
            print("| %s | not converted: %s | | | | | |" % (name, conv.stderr.strip()))
            failed = True
            continue
        size = tuple(int(v) * scale for v in conv.stdout.split())
        lu_png, pov_png = os.path.join(work, name + "_lucent.png"), os.path.join(work, name + "_povray.png")
        lu, po = [], []
        tsv = open(os.path.join(work, "rounds.tsv"), "a")
        # lucent works in the scene's folder (its file names are relative to it).
        os.chdir(os.path.dirname(scene))
        try:
            for r in range(rounds):
                order = ["lucent", "povray"] if r % 2 == 0 else ["povray", "lucent"]
                for who in order:
                    if who == "lucent":
                        lu.append(run_lucent(lucent, scene, lu_png, size, threads))
                    else:
                        po.append(run_povray(pov, pov_png, size, threads, work))
                    got = (lu if who == "lucent" else po)[-1]
                    tsv.write("%s\t%d\t%s\t%.4f\t%.4f\t%d\n" % (name, r, who, got[0], got[1], got[2]))
        except RuntimeError as e:
            lines = [l.strip() for l in str(e).splitlines() if l.strip()]
            why = next((l for l in lines[1:] if "error" in l), lines[-1])
            print("| %s | failed: %s %s | | | | | |" % (name, lines[0], why))
            failed = True
            continue
        finally:
            tsv.close()
        diff = subprocess.run([lucent, "diff", lu_png, pov_png], capture_output=True, text=True).stdout
        m = re.search(r"pixels_over=(\d+) pixels=(\d+).*mae=([0-9.]+)", diff)
        pixels = "%s of %s, %s" % (m.group(1), m.group(2), m.group(3)) if m else diff.strip()
        process = summary([p[0] / l[0] for l, p in zip(lu, po)])
        render = summary([p[1] / l[1] for l, p in zip(lu, po)])
        print("| %s | %.0f k / %.0f k | %.3f / %.3f | **%.2f** [%.2f-%.2f] | %.3f / %.3f | **%.2f** [%.2f-%.2f] | %s |" % (
            name, lu[0][2] / 1e3, po[0][2] / 1e3,
            statistics.median(l[0] for l in lu), statistics.median(p[0] for p in po), *process,
            statistics.median(l[1] for l in lu), statistics.median(p[1] for p in po), *render, pixels))
        sys.stdout.flush()
    print()
    print("(rays: lucent's rays per sample times the pixels; POV-Ray's camera and reflected rays plus its shadow "
          "ray tests. Process CPU includes parsing, building, rendering and writing the PNG.)")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
