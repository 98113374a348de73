"""Progress callbacks, and interruption by a callback or by SIGINT (Ctrl-C)."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import femto
from conftest import small_scene

# A render far longer than any test may take: an interruption must end it early.
LONG = dict(spp=100000, seed=4)


def test_progress_is_called_from_this_thread():
    # Catches a callback never called, called from a render thread, or ending below the total.
    calls = []

    def progress(done, total):
        calls.append((done, total, threading.current_thread() is threading.main_thread()))

    femto.render(small_scene(), spp=6, progress=progress)
    assert calls, "progress was never called"
    assert all(on_main for _, _, on_main in calls)
    done = [d for d, _, _ in calls]
    assert done == sorted(done) and len(set(done)) == len(done)
    assert calls[-1][:2] == (6, 6)


def test_callback_raising_keyboard_interrupt_stops_the_render():
    # Catches a stop request that is ignored (the render would run for minutes) or an exception
    # that leaves the module unusable.
    reference = femto.render(small_scene(), spp=2, seed=9).transient

    def progress(done, total):
        raise KeyboardInterrupt

    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        femto.render(small_scene(), progress=progress, **LONG)
    assert time.monotonic() - start < 20
    again = femto.render(small_scene(), spp=2, seed=9).transient
    assert np.array_equal(again, reference)


def test_other_callback_errors_propagate():
    # Catches an exception from the callback swallowed or turned into another type.
    def progress(done, total):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        femto.render(small_scene(), progress=progress, **LONG)


def test_sigint_interrupts_cleanly():
    # Catches Ctrl-C ignored while the GIL is released (Python only runs signal handlers when
    # asked), and a render that keeps running in the background afterwards.
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        femto.render(small_scene(), **LONG)
    elapsed = time.monotonic() - start
    timer.join()
    assert 0.5 <= elapsed < 20
    # Nothing is left running: a new render is as fast as usual and gives the same bits.
    assert np.array_equal(femto.render(small_scene(), spp=2, seed=9).transient,
                          femto.render(small_scene(), spp=2, seed=9, threads=1).transient)


def test_ctrl_c_from_outside_ends_a_script(tmp_path):
    # Catches Ctrl-C (SIGINT from outside, as a terminal sends it) not ending a Python program
    # stuck in a render: the program must end by KeyboardInterrupt within seconds.
    import subprocess
    import sys
    script = tmp_path / "long_render.py"
    script.write_text(
        "import sys, femto\n"
        "scene = femto.load_scene()['scene']\n"
        "scene['camera']['resolution'] = [24, 18]\n"
        "print('rendering', flush=True)\n"
        "femto.render(scene, spp=100000)\n"
        "print('finished', flush=True)\n")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    assert proc.stdout.readline().strip() == "rendering"
    time.sleep(0.5)
    start = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert time.monotonic() - start < 20
    assert "KeyboardInterrupt" in err and "finished" not in out
    assert proc.returncode != 0
