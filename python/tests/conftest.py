"""Shared fixtures for the femto Python module's tests (python/tests, run by ctest as `python`).

The suite compares the module with the femto command, so it needs both: PYTHONPATH names the
folder holding femto*.so and FEMTO_BINARY the program (CMake sets both for ctest).
"""
import copy
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("FEMTO_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
DEFAULT_SCENE = json.loads((SOURCE_DIR / "data" / "scenes" / "default.json").read_text())


def femto_binary():
    path = os.environ.get("FEMTO_BINARY")
    if not path:
        pytest.skip("FEMTO_BINARY is not set (ctest sets it)")
    return path


def small_scene(width=24, height=18, bins=24):
    """The default scene (fog, glass sphere, spot light) at a small resolution and window."""
    scene = copy.deepcopy(DEFAULT_SCENE)
    scene["camera"]["resolution"] = [width, height]
    scene["time"]["bins"] = bins
    scene["time"]["bin_width"] = 100
    return scene


def run_femto(*args, check=True):
    """Runs the femto command; returns the CompletedProcess (text output)."""
    proc = subprocess.run([femto_binary(), *map(str, args)], capture_output=True, text=True)
    if check and proc.returncode != 0:
        raise AssertionError(f"femto {' '.join(map(str, args))} failed: {proc.stderr}")
    return proc


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(small_scene()))
    return path


def cli_render(scene_path, out_dir, *flags):
    """`femto render` into out_dir; returns (transient.npy, render.json as a dict)."""
    run_femto("render", scene_path, "--out", out_dir, "--frames", "none", "--no-previews",
              "--quiet", *flags)
    out = pathlib.Path(out_dir)
    return np.load(out / "transient.npy"), json.loads((out / "render.json").read_text())
