"""Shared fixtures: the built-in robots and schedule."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # offscreen rendering; before any test module imports mujoco

import pytest

from zmpwalk import RobotModel, Schedule, load_robot


@pytest.fixture(scope="session")
def hubo() -> RobotModel:
    return load_robot("hubo")


@pytest.fixture(scope="session")
def schedule() -> Schedule:
    return Schedule.hubo()


@pytest.fixture(scope="session")
def mju() -> RobotModel:
    return load_robot("mju-biped")
