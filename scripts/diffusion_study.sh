#!/usr/bin/env bash
# When does a pulse's wavefront become Gaussian? The seed paper's Fig. 12 medium
# (sigma_t = 4.1/mm, eta = 1), isotropic and g = 0.5, simulated with `femto diffusion`;
# prints t* (in ps, mean free times and transport mean free paths) for thresholds 2%, 5%, 10%.
# Numbers and discussion: docs/diffusion.md.
#   scripts/diffusion_study.sh [OUT_DIR]        (default ./diffusion-study)
#   PHOTONS=1e6 SEED=2 scripts/diffusion_study.sh   (defaults: 2e6 photons, seed 1)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FEMTO_BUILD_DIR:-$root/build}"
out="${1:-$PWD/diffusion-study}"
photons="${PHOTONS:-2e6}"
seed="${SEED:-1}"

if [ ! -x "$build/femto" ]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$build" --target femto

# Mean free time 1 / (sigma_t c) = 0.81357 ps; plots at 1, 3, 10, 30 (and 60) mean free times.
common=(--sigma-s 4.1 --sigma-a 0 --eta 1 --photons "$photons" --seed "$seed" --t-bins 240)
"$build/femto" diffusion "${common[@]}" --g 0 --t-end 48.814 --r-max 8 --r-bins 160 \
  --plot-times 0.8136,2.4407,8.1357,24.407 --out "$out/isotropic"
"$build/femto" diffusion "${common[@]}" --g 0.5 --t-end 65.086 --r-max 12 --r-bins 200 \
  --plot-times 2.4407,8.1357,24.407,48.814 --out "$out/g0.5"

python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def f(x, fmt="{:.2f}"):
    return "not reached" if x is None else fmt.format(x)
print("\nt*: the distance to the model stays below the threshold (mft = mean free times, "
      "tmfp = transport mean free paths)")
print("\n| medium | threshold | Gaussian of same <r^2>: t* (ps) | (mft) | (tmfp) | diffusion Green's fn (mft) | Paasschens (mft) |")
print("|---|---|---|---|---|---|---|")
for name in ("isotropic", "g0.5"):
    s = json.load(open(f"{out}/{name}/summary.json"))
    dif = s["models"]["diffusion"]["distance_below_threshold_by_threshold"]
    paa = s["models"]["paasschens"]["distance_below_threshold_by_threshold"]
    for row, d, p in zip(s["transition"]["by_threshold"], dif, paa):
        print(f"| {name} | {100 * row['threshold']:g}% | {f(row['t_star_ps'])} | {f(row['t_star_mean_free_times'])} | "
              f"{f(row['t_star_transport_mean_free_paths'])} | {f(d['t_star_mean_free_times'])} | "
              f"{f(p['t_star_mean_free_times'])} |")
for name in ("isotropic", "g0.5"):
    s = json.load(open(f"{out}/{name}/summary.json"))
    m, t = s["models"], s["transition"]
    print(f"\n{name}: smallest distance {t['smallest_distance']:.4f}, largest noise floor "
          f"{t['largest_noise_floor']:.4f}; max |z| of <r^2> vs exact {m['persistent_random_walk']['r2_max_abs_z']:.2f}; "
          f"{s['run']['photons']} photons in {s['run']['seconds']:.1f} s")
    for p in s["at_plot_times"]:
        print(f"  t = {p['t_ps']:.3f} ps ({p['mean_free_times']:.1f} mft): distance to the Gaussian "
              f"{f(p['gaussian_distance'], '{:.4f}')}, to diffusion {f(p['diffusion_distance'], '{:.4f}')}, "
              f"to Paasschens {f(p['paasschens_distance'], '{:.4f}')}")
print(f"\nplots: {out}/*/fluence.png and distance.png")
PY
