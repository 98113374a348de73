#!/usr/bin/env python3
"""Equal-time error of femto's integrators on one scene, against a long reference render.

Each integrator's passes are calibrated to --seconds of render time, then it renders --seeds
times; the error of a render is its relative RMSE over the pixels where the reference is
non-zero, steady (summed over time) and transient (per bin). Prints the median and the RMS of
the renders' errors, and ratios against the first integrator. Plain Python (no NumPy): it reads
transient.npy itself.

  python3 bench/equal_time.py data/scenes/lens_floor.json --ref light:6e7 \\
      --integrators photons,hybrid --seconds 8 --seeds 6
"""
import argparse
import array
import ast
import json
import math
import os
import statistics
import struct
import subprocess
import sys
import tempfile

from host import cpu_model


def render(femto, scene, args, out):
    cmd = [femto, "render", scene, "--out", out, "--quiet", "--no-previews"] + args
    subprocess.run(cmd, check=True)
    with open(os.path.join(out, "render.json")) as f:
        return json.load(f)["timing"]["render_seconds"]


def load(out):
    """transient.npy as (flat float32 array, H, W, values per pixel)."""
    with open(os.path.join(out, "transient.npy"), "rb") as f:
        data = f.read()
    header_len = struct.unpack("<H", data[8:10])[0]
    header = ast.literal_eval(data[10 : 10 + header_len].decode())
    shape = header["shape"]
    values = array.array("f")
    values.frombytes(data[10 + header_len :])
    per_pixel = 1
    for n in shape[2:]:
        per_pixel *= n
    return values, shape[0], shape[1], per_pixel


def errors(values, ref, mask, per_pixel):
    """Steady and transient relative RMSE over the masked pixels."""
    num_s = den_s = num_t = den_t = 0.0
    for p, on in enumerate(mask):
        if not on:
            continue
        base = p * per_pixel
        s = r = 0.0
        for i in range(base, base + per_pixel):
            x, y = values[i], ref[i]
            s += x
            r += y
            num_t += (x - y) ** 2
            den_t += y * y
        num_s += (s - r) ** 2
        den_s += r * r
    return math.sqrt(num_s / den_s), math.sqrt(num_t / den_t)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--femto", default="build/femto")
    ap.add_argument("--ref", default="light:6e7", help="INTEGRATOR:WORK (light paths for light, else passes)")
    ap.add_argument("--integrators", default="photons,hybrid",
                    help='comma-separated; an entry may carry flags: "hybrid --photon-aim off"')
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    threads = ["--threads", str(a.threads)]
    work_flag = lambda kind, n: ["--light-paths", n] if kind == "light" else ["--spp", n]
    print(f"equal_time.py: {cpu_model()}, {a.threads} threads, {a.seconds} s per render, {a.seeds} seeds")
    with tempfile.TemporaryDirectory() as tmp:
        ref_kind, _, ref_work = a.ref.partition(":")
        if not ref_kind or not ref_work:
            ap.error(f"--ref {a.ref}: expected INTEGRATOR:WORK, e.g. light:6e7")
        t = render(a.femto, a.scene, ["--integrator", ref_kind, "--seed", "1000000"] + work_flag(ref_kind, ref_work) + threads, os.path.join(tmp, "ref"))
        ref, h, w, per_pixel = load(os.path.join(tmp, "ref"))
        mask = [any(ref[p * per_pixel + i] != 0 for i in range(per_pixel)) for p in range(h * w)]
        print(f"reference: {a.ref}, {t:.1f} s; {sum(mask)} of {h * w} pixels with light")
        first = None
        for entry in a.integrators.split(","):
            kind, *extra = entry.split()  # "hybrid --photon-aim off": an integrator and its flags
            out = os.path.join(tmp, "run")
            t = render(a.femto, a.scene, ["--integrator", kind, "--seed", "1"] + work_flag(kind, "8") + extra + threads, out)
            work = max(1, int(8 * a.seconds / t))
            seconds, steady, transient = [], [], []
            for seed in range(1, a.seeds + 1):
                seconds.append(render(a.femto, a.scene, ["--integrator", kind, "--seed", str(seed)] + work_flag(kind, str(work)) + extra + threads, out))
                v, _, _, _ = load(out)
                e_s, e_t = errors(v, ref, mask, per_pixel)
                steady.append(e_s)
                transient.append(e_t)
            rms = lambda e: math.sqrt(sum(x * x for x in e) / len(e))
            row = (statistics.median(steady), statistics.median(transient), rms(steady), rms(transient))
            first = first or row
            print(f"{entry:8s} work {work:8d}  {statistics.mean(seconds):5.2f} s  median steady {row[0]:.4f} "
                  f"({first[0] / row[0]:.2f}x), transient {row[1]:.4f} ({first[1] / row[1]:.2f}x)  "
                  f"RMS steady {row[2]:.4f}, transient {row[3]:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
