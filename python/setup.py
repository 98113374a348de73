"""Builds the femto module with the project's CMake (docs/python.md).

    pip install --no-build-isolation ./python

runs CMake on the repository (Release, tests off) for the interpreter running pip, builds the
target femto_python and installs the resulting femto*.so. Environment: FEMTO_JOBS (parallel
jobs, default 2), FEMTO_CMAKE_ARGS (extra CMake arguments, space-separated).
"""
import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent.parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = pathlib.Path(self.build_temp).resolve() / "cmake"
        args = ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                "-DFEMTO_BUILD_TESTS=OFF", "-DFEMTO_PYTHON=ON",
                f"-DPython3_EXECUTABLE={sys.executable}"]
        if shutil.which("ninja"):
            args += ["-G", "Ninja"]
        args += os.environ.get("FEMTO_CMAKE_ARGS", "").split()
        subprocess.run(args, check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "femto_python", "-j",
                        os.environ.get("FEMTO_JOBS", "2")], check=True)
        built = sorted((build / "python").glob("femto*.so"))
        if not built:
            raise RuntimeError(f"the CMake build made no femto*.so in {build / 'python'}: "
                               "see its messages (pybind11-dev and python3-dev are needed)")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


# packages=[]: one extension module and no Python packages (python/src holds C++ only).
setup(ext_modules=[Extension("femto", sources=[])], packages=[],
      cmdclass={"build_ext": CMakeBuild})
