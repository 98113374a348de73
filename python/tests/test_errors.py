"""Bad scenes raise femto.SceneError with the command's message; bad keywords ValueError."""
import json

import pytest

import femto
from conftest import run_femto, small_scene


def test_scene_error_names_file_key_and_value(tmp_path):
    # Catches a message that differs from the command's or loses the file, key or value.
    scene = small_scene()
    scene["camera"]["fov"] = "wide"
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(femto.SceneError) as error:
        femto.load_scene(path)
    message = str(error.value)
    assert str(path) in message and "/camera/fov" in message and "wide" in message
    cli = run_femto("render", path, "--out", tmp_path / "out", check=False)
    assert cli.returncode == 2
    assert message in cli.stderr
    assert not (tmp_path / "out").exists()
    # render raises the same, and SceneError is a ValueError.
    with pytest.raises(femto.SceneError, match="/camera/fov"):
        femto.render(str(path), spp=1)
    assert issubclass(femto.SceneError, ValueError)


def test_scene_error_for_dict_and_missing_file(tmp_path):
    # Catches dict scenes or unreadable paths escaping as another exception type.
    scene = small_scene()
    scene["time"]["bins"] = -3
    with pytest.raises(femto.SceneError, match=r"<dict>: /time/bins"):
        femto.render(scene)
    with pytest.raises(femto.SceneError, match="nowhere.json"):
        femto.load_scene(tmp_path / "nowhere.json")
    with pytest.raises(TypeError):
        femto.render(42)


def test_load_scene_summarises():
    # Catches load_scene not reading what render would (size, window, integrator choice).
    info = femto.load_scene(small_scene(30, 20, 12))
    assert (info["width"], info["height"]) == (30, 20)
    assert info["time_axis"]["bins"] == 12
    assert info["media"] == ["fog"]
    assert info["integrator"] in ("path", "photons", "hybrid", "beams", "light")
    assert info["scene"]["camera"]["resolution"] == [30, 20]
    assert femto.load_scene()["source"] == "<default scene>"


@pytest.mark.parametrize("keywords, pattern", [
    ({"spp": 0}, r"femto.render: spp: must be in \[1, 10000000\] \(got '0'\)"),
    ({"spp": "many"}, r"spp: expected an integer \(got 'many'\)"),
    ({"distance_sampling": "fast"}, r"distance_sampling: expected mfp, time_uniform, mis or mixture"),
    ({"alpha": 0.5}, r"alpha: applies to the kernel film only"),
    ({"photon_radius": 1.0, "integrator": "path"}, r"photon_radius: applies to photon mapping"),
    ({"seed": -1}, r"seed: expected a non-negative integer"),
])
def test_bad_keyword_values(keywords, pattern):
    # Catches a bad value accepted silently or reported without the keyword and the value.
    with pytest.raises(ValueError, match=pattern) as error:
        femto.render(small_scene(), **keywords)
    assert not isinstance(error.value, femto.SceneError)


def test_unknown_keywords():
    # Catches a typo accepted silently, and the command's output options accepted here.
    with pytest.raises(TypeError, match="spps"):
        femto.render(small_scene(), spps=4)
    with pytest.raises(TypeError, match="out"):
        femto.render(small_scene(), out="somewhere")
    with pytest.raises(TypeError, match="no_onset_reflection"):
        femto.render(small_scene(), no_onset_reflection="yes")
