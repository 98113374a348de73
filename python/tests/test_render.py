"""femto.render against the femto command, and the result's arrays, time axis and record."""
import gc
import json
import threading
import time

import numpy as np
import pytest

import femto
from conftest import cli_render, small_scene


def test_bits_equal_the_command(scene_file, tmp_path):
    # Catches any difference between the module's and the command's path from scene and flags to
    # film (option handling, seeding, the film's post-processing): the arrays must be identical.
    expected, record = cli_render(scene_file, tmp_path / "cli", "--spp", 3, "--seed", 7)
    result = femto.render(scene_file, spp=3, seed=7)
    assert result.transient.dtype == np.float32
    assert result.transient.shape == expected.shape
    assert np.array_equal(result.transient, expected)
    # The record matches render.json where both describe the same render.
    for key in ("settings", "time_axis", "film", "counters", "energy", "media", "scene",
                "complete", "femto_version", "femto_build",
                "femto_instruction_set"):
        assert result.meta[key] == record[key], key
    assert result.meta["progress"]["units_done"] == record["progress"]["units_done"]


def test_bits_do_not_depend_on_threads_or_scene_form(scene_file):
    # Catches a scene read differently as dict, JSON text or path, and thread-count dependence.
    scene = small_scene()
    by_path = femto.render(scene_file, spp=2, seed=3, threads=1).transient
    by_dict = femto.render(scene, spp=2, seed=3, threads=2).transient
    by_text = femto.render(json.dumps(scene), spp=2, seed=3).transient
    assert np.array_equal(by_path, by_dict)
    assert np.array_equal(by_path, by_text)


def test_overrides_equal_the_command_flags(scene_file, tmp_path):
    # Catches a keyword mapped to the wrong option: each set must give the command's bits.
    cases = [
        ({"distance_sampling": "mis", "connection_sampling": "collision"},
         ["--distance-sampling", "mis", "--connection-sampling", "collision"]),
        ({"reconstruction": "kernel", "alpha": 0.7, "first_pass_spp": 2, "integrator": "path"},
         ["--reconstruction", "kernel", "--alpha", "0.7", "--first-pass-spp", "2",
          "--integrator", "path"]),
        ({"max_depth": 2, "direction_sampling": "angular"},
         ["--max-depth", "2", "--direction-sampling", "angular"]),
        ({"integrator": "light", "light_paths": 3000}, ["--integrator", "light", "--light-paths", "3000"]),
        ({"russian_roulette": "1,0.5"}, ["--russian-roulette", "1,0.5"]),
        ({"integrator": "photons", "photons": 2000, "photon_radius": 5.0},
         ["--integrator", "photons", "--photons", "2000", "--photon-radius", "5"]),
    ]
    for i, (keywords, flags) in enumerate(cases):
        expected, record = cli_render(scene_file, tmp_path / f"cli{i}", "--spp", 2, "--seed", 5,
                                      *flags)
        result = femto.render(scene_file, spp=2, seed=5, **keywords)
        assert np.array_equal(result.transient, expected), keywords
        kernel = keywords.get("reconstruction") == "kernel"
        assert (result.kernel_bandwidth_ps is not None) == kernel
        if kernel:
            bandwidth = result.kernel_bandwidth_ps
            assert bandwidth.shape == expected.shape[:2] and bandwidth.base is result
            assert np.isfinite(bandwidth).all() and (bandwidth > 0).any()
        assert result.meta["settings"] == record["settings"], keywords


def test_default_scene_renders():
    # Catches the built-in scene (scene=None) not being the command's default scene.
    r = femto.render(spp=1, seed=1, max_depth=1)
    assert r.meta["scene"]["source"] == "<default scene>"
    assert r.transient.shape == (192, 256, 128, 3)


def test_shapes_time_axis_and_steady():
    # Catches a wrong layout (H, W, T, 3), a time axis off by half a bin, or a steady image
    # that is not the sum over bins.
    scene = small_scene(width=20, height=10, bins=16)
    r = femto.render(scene, spp=2)
    assert r.transient.shape == (10, 20, 16, 3)
    assert r.steady.shape == (10, 20, 3) and r.steady.dtype == np.float32
    assert r.peak_time.shape == (10, 20)
    axis = r.time_axis
    t0, w = scene["time"]["t_start"], scene["time"]["bin_width"]
    assert axis["bins"] == 16 and axis["t_start_ps"] == t0 and axis["bin_width_ps"] == w
    assert np.allclose(axis["edges_ps"], t0 + w * np.arange(17))
    assert np.allclose(axis["centers_ps"], t0 + w * (np.arange(16) + 0.5))
    assert np.allclose(axis["centers_opl_mm"], axis["centers_ps"] * femto.speed_of_light_mm_per_ps)
    assert np.isclose(axis["start_opl_mm"], t0 * 0.299792458)
    # steady is the film's own sum of each pixel's bins (float32 rounding apart).
    assert np.allclose(r.steady, r.transient.sum(axis=2, dtype=np.float64), rtol=1e-5, atol=1e-12)
    assert r.transient.sum() > 0
    assert r.complete and r.meta["complete"]


def test_arrays_are_views_of_the_film():
    # Catches a copy (memory doubled) or a film freed while an array still views it.
    r = femto.render(small_scene(), spp=1)
    t = r.transient
    assert t.base is r and not t.flags.owndata and t.flags.c_contiguous
    assert np.shares_memory(t, r.transient)
    assert r.steady.base is r
    copy = t.copy()
    del r
    gc.collect()
    junk = [np.ones(t.shape, np.float32) for _ in range(3)]  # would reuse freed memory
    assert np.array_equal(t, copy)
    del junk


def test_gil_is_released_while_rendering():
    # Catches a render that holds the GIL: another Python thread must run meanwhile.
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    thread = threading.Thread(target=count)
    thread.start()
    before = len(ticks)
    # About 0.2 s of rendering: ~200 ticks when the GIL is free, none while a render holds it
    # (a render of 8 spp took 30 ms, too short for a bound under a loaded machine).
    femto.render(small_scene(), spp=96, seed=2)
    during = len(ticks) - before
    stop.set()
    thread.join()
    assert during > 20
