#!/usr/bin/env python3
"""Equal-time error of lucent's sampling choices on one scene.

Renders SCENE once at a high sample count as the reference, then with each setting given
on the command line, and prints the CPU time and the RMSE against the reference (linear
radiance, all channels) and the mean absolute error of each. Settings are lucent options, e.g.:

  python3 scripts/equal_time.py scenes/pathtraced.test --size-scale 0.5 --ref-spp 4096 \\
      "--sampler sobol --spp 64" "--sampler independent --spp 64" \\
      "--sampler sobol --spp 256 --noise-threshold 0.05"

Images go through Radiance HDR files (read here, run-length encoding included), so
nothing beyond Python 3 and numpy is needed.
"""
import argparse
import os
import resource
import shlex
import subprocess
import sys
import tempfile

import numpy as np


def read_hdr(path):
    """A Radiance RGBE file as a float array of shape (height, width, 3)."""
    with open(path, "rb") as f:
        data = f.read()
    head_end = data.index(b"\n\n") + 2
    line_end = data.index(b"\n", head_end)
    parts = data[head_end:line_end].split()
    height, width = int(parts[1]), int(parts[3])
    pos = line_end + 1
    out = np.zeros((height, width, 4), dtype=np.uint8)
    for y in range(height):
        if width >= 8 and width < 32768 and data[pos] == 2 and data[pos + 1] == 2 and data[pos + 2] < 128:
            pos += 4  # new-style run-length encoding: the four channels one after the other
            for c in range(4):
                x = 0
                while x < width:
                    n = data[pos]
                    pos += 1
                    if n > 128:
                        n -= 128
                        out[y, x : x + n, c] = data[pos]
                        pos += 1
                    else:
                        out[y, x : x + n, c] = np.frombuffer(data[pos : pos + n], dtype=np.uint8)
                        pos += n
                    x += n
        else:
            out[y] = np.frombuffer(data[pos : pos + 4 * width], dtype=np.uint8).reshape(width, 4)
            pos += 4 * width
    e = out[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    return out[..., :3].astype(np.float64) * scale[..., None]


def render(lucent, scene, options, out):
    """Runs one render; returns its CPU seconds (user + system of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    cmd = [lucent, "render", scene, "-o", out, "--quiet"] + options
    subprocess.run(cmd, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("settings", nargs="+", help="lucent options of one run, quoted")
    ap.add_argument("--lucent", default="target/release/lucent")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--ref-options", default="--sampler sobol")
    ap.add_argument("--common", default="", help="options for every run (e.g. '--threads 1')")
    ap.add_argument("--reference", help="keep the reference here (an .hdr file), and reuse it if it exists")
    args = ap.parse_args()
    common = shlex.split(args.common)
    with tempfile.TemporaryDirectory() as tmp:
        ref_path = args.reference or os.path.join(tmp, "ref.hdr")
        if os.path.exists(ref_path):
            print(f"reference: {ref_path}")
        else:
            opts = common + shlex.split(args.ref_options) + ["--spp", str(args.ref_spp)]
            t = render(args.lucent, args.scene, opts, ref_path)
            print(f"reference: {args.ref_spp} spp, {t:.1f} CPU-s")
        ref = read_hdr(ref_path)
        print(f"reference mean {ref.mean():.4f}")
        # RMSE, and the mean absolute error, which a few bright outliers (caustic
        # fireflies) sway less.
        print("| setting | CPU-s | RMSE | mean abs. error |")
        print("|---|---|---|---|")
        for k, s in enumerate(args.settings):
            path = os.path.join(tmp, f"run{k}.hdr")
            t = render(args.lucent, args.scene, common + shlex.split(s), path)
            img = read_hdr(path)
            rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
            mae = float(np.mean(np.abs(img - ref)))
            print(f"| `{s}` | {t:.1f} | {rmse:.5f} | {mae:.5f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
