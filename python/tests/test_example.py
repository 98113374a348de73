"""examples/python_quickstart.py runs and writes its two pictures."""
import os
import subprocess
import sys

from conftest import SOURCE_DIR


def test_quickstart_example_writes_its_pngs(tmp_path):
    # Catches the example drifting from the module's API (it is what the README points to).
    script = SOURCE_DIR / "examples" / "python_quickstart.py"
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(script), "--spp", "1", "--out", str(tmp_path)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    for name in ("pixel_profile.png", "peak_time.png"):
        data = (tmp_path / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000, name
