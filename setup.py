"""pip's build of the `cradle` package: CMake builds the `cradle` program and the `_cradle` module,
then setuptools packages the build tree's package folder (build/python/cradle, laid out by
python/link_package.cmake: the Python files, configs, TeachMyAgent data, figure script, program).

The CMake build folder is $CRADLE_BUILD_DIR, else the source tree's build/ (the one `make build`
uses, configured here when it is not yet), so `pip install --no-build-isolation .` after
`make build` only relinks what changed. Only the program and the module are built, no tests.
"""

import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

SOURCE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.abspath(os.environ.get("CRADLE_BUILD_DIR") or os.path.join(SOURCE, "build"))
PACKAGE = os.path.join(BUILD, "python", "cradle")
# setuptools' own intermediate folders, kept inside the CMake build folder.
STAGING = os.path.join(BUILD, "pip")
os.makedirs(STAGING, exist_ok=True)
os.makedirs(os.path.dirname(PACKAGE), exist_ok=True)


def _version():
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        return re.search(r"project\(cradle VERSION ([0-9.]+)", f.read()).group(1)


def _run(command):
    print("cradle:", " ".join(command), flush=True)
    try:
        subprocess.run(command, check=True)
    except FileNotFoundError:
        sys.exit(f"cradle: {command[0]} is not installed (run scripts/install-deps.sh)")
    except subprocess.CalledProcessError as error:
        sys.exit(f"cradle: '{' '.join(command)}' failed with exit status {error.returncode}")


_built = False


def cmake_build():
    """Configures BUILD when needed and builds the program and the module (once per setup run)."""
    global _built
    if _built:
        return
    if not os.path.exists(os.path.join(BUILD, "CMakeCache.txt")):
        generator = ["-G", "Ninja"] if shutil.which("ninja") else []
        _run(["cmake", "-S", SOURCE, "-B", BUILD, *generator, "-DCMAKE_BUILD_TYPE=Release"])
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
    _run(["cmake", "--build", BUILD, "-j", jobs, "--target", "cradle", "_cradle"])
    module = os.path.join(PACKAGE, "_cradle" + sysconfig.get_config_var("EXT_SUFFIX"))
    if not os.path.exists(module):
        sys.exit(f"cradle: {BUILD} holds no {os.path.basename(module)}: its module was built for "
                 f"another Python than {sys.executable} (CMake's Python3_EXECUTABLE)")
    _built = True


class BuildPy(build_py):
    """Builds with CMake first: the package folder setuptools copies is CMake's."""

    def run(self):
        cmake_build()
        super().run()


class BuildExt(build_ext):
    """The `_cradle` module comes from CMake, not from setuptools' compiler."""

    def run(self):
        cmake_build()
        # An editable install imports the build tree's package folder itself.
        if self.editable_mode or self.inplace:
            return
        for ext in self.extensions:
            built = os.path.join(PACKAGE, os.path.basename(self.get_ext_filename(ext.name)))
            target = self.get_ext_fullpath(ext.name)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            self.copy_file(built, target)


setup(
    name="cradle",
    version=_version(),
    description="Cradle: agents that learn on their own (BabyBench/MIMo in MuJoCo, TeachMyAgent, "
    "SaMI), in C++ with a Python package",
    python_requires=">=3.9",
    install_requires=["numpy"],
    packages=["cradle"],
    package_dir={"": os.path.relpath(os.path.dirname(PACKAGE), SOURCE)},
    package_data={
        "cradle": [
            "cradle-resources.txt",
            "configs/*.yml",
            "configs/curricula/*.yml",
            "data/teachmyagent/*",
            "bin/cradle",
        ]
    },
    ext_modules=[Extension("cradle._cradle", sources=[])],
    scripts=[os.path.join("python", "scripts", "cradle")],
    cmdclass={"build_py": BuildPy, "build_ext": BuildExt},
    options={
        "build": {"build_base": STAGING},
        "egg_info": {"egg_base": os.path.relpath(STAGING, SOURCE)},
    },
    zip_safe=False,
)
