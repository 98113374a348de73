"""femto.diffusion and femto.uniformity against the femto command and the exact values."""
import json

import numpy as np
import pytest

import femto
from conftest import run_femto


def test_diffusion_arrays_match_the_command_and_theory(tmp_path):
    # Catches keywords mapped to the wrong flags (t* would differ from the command's) and
    # tallies that disagree with the exact energy (weighted absorption makes it exact up to
    # rounding) and <r^2> (4 standard errors per bin).
    keywords = dict(sigma_s=4.1, sigma_a=0.01, photons=4000, t_bins=30, r_bins=25, seed=3)
    d = femto.diffusion(**keywords)
    assert d["u"].shape == (30, 25) and d["u_diffusion"].shape == (30, 25)
    assert d["time_ps"].shape == (30,) and d["r_mm"].shape == (25,)
    assert d["photons"] == 4000
    assert np.allclose(d["energy"], d["energy_exact"], rtol=1e-9, atol=0)
    r2, err, exact = d["r2"], d["r2_err"], d["r2_exact"]
    assert np.all(err > 0)
    assert np.all(np.abs(r2 - exact) <= 4 * err)
    out = tmp_path / "cli"
    run_femto("diffusion", "--sigma-s", 4.1, "--sigma-a", 0.01, "--photons", 4000, "--t-bins", 30,
              "--r-bins", 25, "--seed", 3, "--out", out, "--quiet")
    summary = json.loads((out / "summary.json").read_text())
    cli_t = summary["transition"]["t_star_ps"]
    assert (cli_t is None and np.isnan(d["t_star"]["t_ps"])) or cli_t == d["t_star"]["t_ps"]
    assert np.isclose(summary["inputs"]["time"]["bin_width_ps"], d["time_ps"][1] - d["time_ps"][0])


def test_diffusion_bad_value():
    # Catches a bad value reaching the simulation.
    with pytest.raises(ValueError, match=r"g: must be in \(-1, 1\)"):
        femto.diffusion(g=1.5)
    with pytest.raises(TypeError):
        femto.diffusion(out="x")


def test_uniformity_matches_the_command(tmp_path):
    # Catches results that differ from the command's summary.json for the same flags.
    u = femto.uniformity(strategy="time_uniform", samples=20000, bins=20, seed=2)
    assert list(u) == ["time_uniform"]
    r = u["time_uniform"]
    assert r["counts"].shape == (20,)
    assert r["counts"].sum() == r["in_range"]
    out = tmp_path / "cli"
    run_femto("uniformity", "--strategy", "time_uniform", "--samples", 20000, "--bins", 20,
              "--seed", 2, "--out", out, "--quiet")
    summary = json.loads((out / "summary.json").read_text())
    (cli,) = [e for e in summary["strategies"] if e["strategy"] == "time_uniform"]
    for key in ("chi2", "chi2_dof", "chi2_p", "ks_d", "ks_p", "in_range", "drawn"):
        assert cli[key] == r[key], key
    assert cli["uniform"] == r["passed"]
    assert np.isclose(r["expected_per_bin"], r["in_range"] / 20)


def test_uniformity_all_strategies_and_keywords():
    # Catches the vector keywords (sensor, light) or lambda_ not reaching the config.
    u = femto.uniformity(samples=2000, bins=10, light=(20, 0, 10), lambda_=0.002)
    assert set(u) == {"mfp", "time_uniform", "line_to_point", "angular", "equiangular"}
    with pytest.raises(ValueError, match="light"):
        femto.uniformity(light=(1, 2))


def test_diffusion_sigint_interrupts():
    # Catches Ctrl-C ignored during a diffusion run (10^10 photons would take hours).
    import os
    import signal
    import threading
    import time
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        femto.diffusion(photons=10**10, t_bins=20, r_bins=20)
    timer.join()
    assert time.monotonic() - start < 20
