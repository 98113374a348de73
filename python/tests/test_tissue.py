"""femto.tissue against the files `femto render` writes for the same tissue scene."""
import json
import time

import numpy as np
import pytest

import femto
from conftest import SOURCE_DIR, run_femto

CUBE60 = SOURCE_DIR / "data" / "scenes" / "cube60.json"


def small_cube(**tissue):
    """A 12 mm cube (Fresnel boundary), two detectors, face images and fluence errors."""
    scene = {
        "tissue": {
            "volume": {"shape": [12, 12, 12], "fill": 1, "voxel": 1.0},
            "labels": [{"label": 1, "mu_a": 0.01, "mu_s": 2.0, "g": 0.8, "n": 1.37}],
            "source": {"type": "pencil", "position": [6, 6, 0], "direction": [0, 0, 1]},
            "time": {"bin_width": 20, "bins": 12},
            "fluence": {"stderr": True},
            "faces": True,
            "detectors": [{"position": [6, 9, 0], "radius": 1.5},
                          {"position": [9, 6, 0], "radius": 1.5, "na": 0.5}],
            "photons": 3000,
            "seed": 5,
        }
    }
    scene["tissue"].update(tissue)
    return scene


def test_outputs_match_the_command_bit_for_bit(tmp_path):
    # Catches arrays in another order, unit or shape than the command's files, and keywords
    # that do not reach the run.
    path = tmp_path / "cube.json"
    path.write_text(json.dumps(small_cube()))
    out = tmp_path / "cli"
    run_femto("render", path, "--out", out, "--photons", 2000, "--seed", 7, "--quiet")
    d = femto.tissue(path, photons=2000, seed=7)
    assert d["fluence"].shape == (12, 12, 12, 12) and d["fluence"].dtype == np.float32
    assert np.array_equal(d["fluence"], np.load(out / "fluence.npy"))
    assert np.array_equal(d["fluence_rate"], np.load(out / "fluence_rate.npy"))
    assert np.array_equal(d["fluence_stderr"], np.load(out / "fluence_stderr.npy"))
    assert np.array_equal(d["tpsf"].astype(np.float32), np.load(out / "tpsf.npy"))
    for face in ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax"):
        assert np.array_equal(d["exitance"][face], np.load(out / f"exitance_{face}.npy")), face
    det = d["detected"]
    info = np.load(out / "detected_photons.npy")
    assert len(det["weight"]) == info.shape[0] > 10
    assert np.array_equal(det["detector"].astype(np.float32), info[:, 0])
    assert np.array_equal(det["weight"].astype(np.float32), info[:, 2])
    assert np.array_equal(det["ppath"].astype(np.float32), np.load(out / "detected_ppath.npy"))
    assert np.array_equal(det["exit"].astype(np.float32), np.load(out / "detected_exit.npy"))
    summary = json.loads((out / "summary.json").read_text())
    assert d["summary"]["absorbed_fraction"] == summary["absorbed_fraction"]
    assert d["summary"]["photons"] == 2000
    assert d["time_ps"].shape == (12,) and d["time_edges_ps"][-1] == 240
    assert d["absorbed_per_label"].shape == (2,)


def test_dict_text_and_threads_give_the_same_bits():
    # Catches results that depend on how the scene is given or on the thread count.
    scene = small_cube(photons=1500)
    a = femto.tissue(scene, threads=1)
    b = femto.tissue(json.dumps(scene), threads=2)
    assert np.array_equal(a["fluence"], b["fluence"])
    assert np.array_equal(a["tpsf"], b["tpsf"])
    assert np.array_equal(a["detected"]["weight"], b["detected"]["weight"])
    assert a["summary"]["energy_balance"] == b["summary"]["energy_balance"]


def test_progress_and_interruption():
    # Catches a progress callback never called or not ending at the total, and a stop request
    # that is ignored (the run would take minutes).
    calls = []
    femto.tissue(small_cube(), photons=20000, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (20000, 20000)
    assert [c[0] for c in calls] == sorted(c[0] for c in calls)

    def stop(done, total):
        raise KeyboardInterrupt

    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        femto.tissue(CUBE60, photons=10**9, progress=stop)
    assert time.monotonic() - start < 60


def test_bad_input():
    # Catches bad values reaching the run, and scenes of the wrong kind accepted.
    with pytest.raises(ValueError, match=r"photons: must be a whole number"):
        femto.tissue(small_cube(), photons=0)
    with pytest.raises(TypeError):
        femto.tissue(small_cube(), photons="many")
    with pytest.raises(ValueError, match="not a tissue scene"):
        femto.tissue({"camera": {}})
    bad = small_cube()
    bad["tissue"]["labels"][0]["mu_s"] = -1
    with pytest.raises(femto.SceneError, match=r"<dict>: /tissue/labels/0/mu_s: must be in"):
        femto.tissue(bad)
    with pytest.raises(ValueError, match="femto.tissue"):
        femto.render(small_cube())
