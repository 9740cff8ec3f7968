"""pip installs Cradle into fresh venvs, offline, and the installed copy runs on its own files.

Run after the build (`.ci/run` does, after `make test`):

    /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/install

pip builds with the CMake build folder $CRADLE_BUILD_DIR, else build/, so after `make build` it
only packages. The source tree stays where it is, so each check asserts that the path the
installed copy resolved lies inside the venv: an installed copy prefers its own data files.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# Debian's Python: a venv with --system-site-packages sees its numpy, setuptools and wheel.
PYTHON = "/usr/bin/python3"
# Variables that would point an installed copy back at the source or build tree.
HIDDEN = ("PYTHONPATH", "PYTHONHOME", "CRADLE_TMA_DATA", "CRADLE_PYTHON", "CRADLE_BINARY")


def environment(venv, **extra):
    env = {k: v for k, v in os.environ.items() if k not in HIDDEN}
    env["PATH"] = os.path.join(venv, "bin") + os.pathsep + env.get("PATH", "")
    env.update(extra)
    return env


def run(command, venv, cwd="/", **extra):
    result = subprocess.run(command, cwd=cwd, env=environment(venv, **extra),
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"{command} failed:\n{result.stdout}\n{result.stderr}"
    return result


def make_venv(root, *pip_args):
    subprocess.run([PYTHON, "-m", "venv", "--system-site-packages", root], check=True)
    # --no-index: the install must not need the network.
    run([os.path.join(root, "bin", "pip"), "install", "-q", "--no-index", "--no-build-isolation",
         *pip_args], root, cwd=SOURCE)
    return root


def site_packages(venv):
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    return os.path.join(venv, "lib", version, "site-packages")


def inside(path, folder):
    return os.path.commonpath([os.path.realpath(path), os.path.realpath(folder)]) == \
        os.path.realpath(folder)


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    return make_venv(str(tmp_path_factory.mktemp("venv")), SOURCE)


# Makes one env of each family, resets and steps it, and prints where the files it used came from.
ENVS_SCRIPT = textwrap.dedent("""
    import json
    import cradle
    from cradle import _cradle

    def steps(env):
        env.reset(seed=0)
        for _ in range(3):
            result = env.step(env.action_space.sample())
        assert len(result) == 5
        env.close()

    steps(cradle.make("BabyBench-SelfTouch"))
    steps(cradle.tma.make(cradle.tma.PARKOUR))
    steps(cradle.sami.make(cradle.sami.ENV_NAMES[0]))
    print(json.dumps({"package": cradle.__file__, "configs": cradle.env.CONFIG_DIR,
                      "tma_data": _cradle.tma_data_dir()}))
""")


def test_package_steps_every_family_on_its_own_files(venv):
    used = json.loads(run([os.path.join(venv, "bin", "python"), "-c", ENVS_SCRIPT],
                          venv).stdout.splitlines()[-1])
    package = os.path.join(site_packages(venv), "cradle")
    for what, path in used.items():
        assert inside(path, package), f"{what}: {path} is not inside {package}"
    assert os.path.isfile(os.path.join(used["tma_data"], "ground_ceiling_cppn.f32"))


def test_cradle_command_runs_the_installed_program(venv, tmp_path):
    cradle = os.path.join(venv, "bin", "cradle")
    assert "Usage" in run([cradle, "--help"], venv).stdout
    version = run([cradle, "--version"], venv).stdout
    assert f"data files: {os.path.join(site_packages(venv), 'cradle')}" in version, version
    # A Parkour episode needs the CPPN weights.
    run([cradle, "tma", "random", "--env", "parkour", "--steps", "20"], venv, cwd=str(tmp_path))


def test_explicit_tma_data_folder_comes_first(venv, tmp_path):
    data = tmp_path / "teachmyagent"
    data.mkdir()
    for name in ("ground_cppn.f32", "ground_ceiling_cppn.f32"):
        shutil.copy(os.path.join(SOURCE, "data", "teachmyagent", name), data)
    printed = run([os.path.join(venv, "bin", "python"), "-c",
                   "from cradle import _cradle; print(_cradle.tma_data_dir())"], venv,
                  CRADLE_TMA_DATA=str(data)).stdout.strip()
    assert printed == str(data)


def test_evaluation_figures_use_the_installed_script(venv, tmp_path):
    # CRADLE_PYTHON is the interpreter that draws figures: this one records the script it runs.
    log = tmp_path / "figures.log"
    recorder = tmp_path / "python"
    recorder.write_text(f'#!/bin/sh\necho "$1" >> {log}\nexec {PYTHON} "$@"\n')
    recorder.chmod(0o755)
    config = tmp_path / "config.yml"
    config.write_text("save_dir: evaluation\nbehavior: self_touch\nscene: base\n")
    run([os.path.join(venv, "bin", "cradle"), "evaluate", "--config", str(config),
         "--episodes", "1", "--duration", "5", "--no-render"], venv, cwd=str(tmp_path),
        CRADLE_PYTHON=str(recorder))
    scripts = log.read_text().split()
    assert scripts, "no figure was drawn"
    package = os.path.join(site_packages(venv), "cradle")
    for script in scripts:
        assert inside(script, package), f"{script} is not inside {package}"
    assert list((tmp_path / "evaluation" / "plots").glob("*.png"))


def test_editable_install_imports_the_build_tree(tmp_path):
    venv = make_venv(str(tmp_path / "venv"), "-e", SOURCE)
    build = os.environ.get("CRADLE_BUILD_DIR") or os.path.join(SOURCE, "build")
    package = run([os.path.join(venv, "bin", "python"), "-c",
                   "import cradle; print(cradle.__file__)"], venv).stdout.strip()
    # The package folder itself: its Python files are links to python/cradle.
    assert os.path.realpath(os.path.dirname(package)) == \
        os.path.realpath(os.path.join(build, "python", "cradle")), package
    # The command runs the build tree's program, which reads the source tree.
    version = run([os.path.join(venv, "bin", "cradle"), "--version"], venv).stdout
    assert f"data files: {SOURCE} (source tree)" in version, version


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    """`make install CMAKE_INSTALL_PREFIX=...` without the rebuild `make install` starts with."""
    build = os.environ.get("CRADLE_BUILD_DIR") or os.path.join(SOURCE, "build")
    folder = tmp_path_factory.mktemp("prefix")
    subprocess.run(["cmake", "--install", build, "--prefix", str(folder)], check=True,
                   capture_output=True)
    return folder


def test_cmake_install_uses_the_data_of_its_prefix(prefix, tmp_path):
    cradle = str(prefix / "bin" / "cradle")
    version = run([cradle, "--version"], str(prefix)).stdout
    assert f"data files: {prefix / 'share' / 'cradle'}" in version, version
    run([cradle, "tma", "random", "--env", "parkour", "--steps", "20"], str(prefix),
        cwd=str(tmp_path))


def test_find_package_builds_a_program_on_the_installed_library(prefix, tmp_path):
    build = tmp_path / "build"
    run(["cmake", "-S", os.path.join(SOURCE, "tests", "install", "consumer"), "-B", str(build),
         f"-DCMAKE_PREFIX_PATH={prefix}"], str(prefix))
    run(["cmake", "--build", str(build)], str(prefix))
    # A program of the user's own is not installed with the data: it is told where they are.
    out = run([str(build / "consumer")], str(prefix),
              CRADLE_TMA_DATA=str(prefix / "share" / "cradle" / "data" / "teachmyagent")).stdout
    assert "5 Parkour steps" in out, out
