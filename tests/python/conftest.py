"""Shared helpers for the Python tests: the reference configs with save_dir in a temp folder."""

import os
import pathlib

import pytest

import cradle

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = {
    "test_installation": ROOT / "configs" / "config_test_installation.yml",
    "selftouch": ROOT / "configs" / "config_selftouch.yml",
    "handregard": ROOT / "configs" / "config_handregard.yml",
}


def cradle_binary():
    """The CLI built next to the package (ctest sets CRADLE_BINARY)."""
    return os.environ.get("CRADLE_BINARY", str(ROOT / "build" / "cradle"))


@pytest.fixture
def make_config(tmp_path):
    """make_config(name, **overrides): a config dict of a reference config, saving under tmp."""

    def make(name, **overrides):
        config = cradle.config_dict(CONFIGS[name])
        config["save_dir"] = str(tmp_path / name)
        config.update(overrides)
        return config

    return make
