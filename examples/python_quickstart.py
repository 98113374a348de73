#!/usr/bin/env python3
"""femto from Python: render the built-in scene, plot one pixel over time and the peak-time image.

    cmake --build build                               # builds build/python/femto*.so
    PYTHONPATH=build/python python3 examples/python_quickstart.py [--spp 8] [--out DIR]

Writes DIR/pixel_profile.png and DIR/peak_time.png (DIR defaults to ./femto-python-out). The
scene is a pulsed spot light in fog behind a glass sphere (data/scenes/default.json); see
docs/python.md for the API.
"""
import argparse
import os
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import femto


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=8, help="samples per pixel (default 8)")
    parser.add_argument("--out", default="femto-python-out", help="folder for the PNGs")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    # The render: a (H, W, T, 3) float32 array of radiance integrated over each time bin.
    last = [-1]

    def progress(done, total):  # called from this thread a few times a second
        percent = 100 * done // total
        if percent != last[0]:
            print(f"\rrendering: {percent:3d}%", end="", flush=True)
            last[0] = percent

    result = femto.render(spp=args.spp, seed=1, progress=progress)
    print()
    transient, axis = result.transient, result.time_axis
    height, width, bins, _ = transient.shape
    print(f"{width} x {height} pixels, {bins} bins of {axis['bin_width_ps']} ps from "
          f"{axis['t_start_ps']} ps; {result.meta['counters']['paths']} camera paths in "
          f"{result.meta['timing']['render_seconds']:.1f} s")

    # One pixel's time profile, luminance per bin: the centre of the brightest 8 x 8 block of
    # the steady image (a block, not a pixel, so that one lucky sample does not choose it).
    luminance = transient @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)  # (H, W, T)
    steady = luminance.sum(axis=2)
    blocks = steady[: height // 8 * 8, : width // 8 * 8].reshape(height // 8, 8, width // 8, 8)
    by, bx = np.unravel_index(np.argmax(blocks.sum(axis=(1, 3))), (height // 8, width // 8))
    y, x = 8 * by + 4, 8 * bx + 4
    fig, ax = plt.subplots(figsize=(7, 4))
    block = luminance[8 * by: 8 * by + 8, 8 * bx: 8 * bx + 8].mean(axis=(0, 1))
    ax.step(axis["centers_ps"], luminance[y, x], where="mid", lw=0.8, label="the pixel")
    ax.step(axis["centers_ps"], block, where="mid", lw=2, label="mean of its 8 x 8 block")
    ax.legend()
    ax.set_xlabel("time (ps)")
    ax.set_ylabel("radiance per bin (luminance)")
    ax.set_title(f"pixel (x={x}, y={y})")
    opl = ax.secondary_xaxis("top", functions=(lambda t: t * femto.speed_of_light_mm_per_ps,
                                               lambda d: d / femto.speed_of_light_mm_per_ps))
    opl.set_xlabel("optical path length (mm)")
    fig.tight_layout()
    fig.savefig(out / "pixel_profile.png", dpi=120)

    # When each pixel is brightest (NaN where no light arrived in the window).
    fig, ax = plt.subplots(figsize=(7, 5))
    image = ax.imshow(result.peak_time, cmap="viridis")
    ax.plot([x], [y], "r+", markersize=12)
    ax.set_title("peak time")
    fig.colorbar(image, ax=ax, label="time of the brightest bin (ps)")
    fig.tight_layout()
    fig.savefig(out / "peak_time.png", dpi=120)
    print(f"wrote {out / 'pixel_profile.png'} and {out / 'peak_time.png'}")


if __name__ == "__main__":
    main()
