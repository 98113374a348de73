#!/usr/bin/env python3
"""Per-pixel variance x time of femto configurations on one scene, renders interleaved.

Each configuration renders the scene once per seed (seeds 100, 101, ...; the configurations
interleaved seed by seed, so a noisy host slows them alike) on one thread. A pixel's steady value
is the sum of its time bins (of bins FIRST to END - 1 only with --bins FIRST:END; mean of the
channels); its variance across the seeds times the configuration's mean render time is its
variance per unit time (lower is better). Pixels are
classed by the mean image of the configurations named in --mask-from: "bright" above 10% of its
peak, "dim" from 0.3% to 10%, "lit" above 0.3%. For each class: the summed variance x time (what
a crop's RMSE measures) and the median over its pixels, then the same over lit pixel-bins of the
transient film. Ratios are against --base (default the first configuration; above 1: better
than it). Needs NumPy.

  python3 bench/variance_time.py data/scenes/laser_fog.json --seeds 8 \\
      --config "path:build/femto:--integrator path --spp 16" \\
      --config "hybrid:build/femto:--integrator hybrid --spp 16" --mask-from hybrid
"""
import argparse
import os
import subprocess
import tempfile
import time

import numpy as np

from host import cpu_model


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--config", action="append", required=True,
                    help="NAME:FEMTO_BINARY:ARGS (ARGS split on spaces)")
    ap.add_argument("--mask-from", default="", help="comma-separated names (default: all)")
    ap.add_argument("--base", default="", help="the configuration ratios are against (default: first)")
    ap.add_argument("--bins", default="", help="FIRST:END, only these time bins (e.g. late light)")
    a = ap.parse_args()
    configs = [c.split(":", 2) for c in a.config]
    names = [c[0] for c in configs]
    films = {n: [] for n in names}
    seconds = {n: 0.0 for n in names}
    with tempfile.TemporaryDirectory() as tmp:
        for s in range(a.seeds):
            for name, binary, args in configs:
                out = os.path.join(tmp, name)
                start = time.monotonic()
                subprocess.run([binary, "render", a.scene, "--seed", str(100 + s), "--threads", "1",
                                "--quiet", "--no-previews", "--out", out] + args.split(),
                               check=True)
                seconds[name] += time.monotonic() - start
                # (H, W, bins, 3) -> (H, W, bins), channels averaged
                film = np.load(os.path.join(out, "transient.npy")).mean(axis=-1)
                if a.bins:
                    first, end = (int(x) for x in a.bins.split(":"))
                    film = film[:, :, first:end]
                films[name].append(film)
    print(f"{cpu_model()}; {a.scene}, {a.seeds} seeds, one thread"
          + (f", bins {a.bins}" if a.bins else ""))
    mask_names = a.mask_from.split(",") if a.mask_from else names
    mean_img = np.mean([np.mean(films[n], axis=0).sum(axis=-1) for n in mask_names], axis=0)
    peak = mean_img.max()
    classes = {
        "bright": mean_img > 0.1 * peak,
        "dim": (mean_img > 0.003 * peak) & (mean_img <= 0.1 * peak),
        "lit": mean_img > 0.003 * peak,
    }
    rows = {}
    for n in names:
        f = np.array(films[n])
        t = seconds[n] / a.seeds
        var = f.sum(axis=-1).var(axis=0, ddof=1) * t
        var_t = f.var(axis=0, ddof=1) * t
        row = {"time": t}
        for c, m in classes.items():
            row[c] = (var[m].sum(), np.median(var[m]))
        row["transient"] = (var_t[classes["lit"]].sum(), np.median(var_t[classes["lit"]]))
        rows[n] = row
    print("pixels: " + ", ".join(f"{c} {int(m.sum())}" for c, m in classes.items()))
    base = rows[a.base or names[0]]
    for n in names:
        r = rows[n]
        line = f"{n:14s} {r['time']:6.2f} s/render"
        for c in ("bright", "dim", "lit", "transient"):
            s, med = r[c]
            line += f" | {c}: sum {s:.3e} ({base[c][0] / s:.3g}x) median {med:.3e}"
            line += f" ({base[c][1] / med:.3g}x)" if med > 0 else " (-)"
        print(line)


if __name__ == "__main__":
    main()
