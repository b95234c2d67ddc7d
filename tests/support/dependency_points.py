"""Where the dependency tests perturb each input and state (tests/fmu/test_dependencies.py,
tests/native/test_native_model_exchange.py): a model's start values, its class's
``dependency_points`` and the tests' own points."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from driveline.catalog import MODELS

#: Points of the tests' own: a layout with the most mounts, each turned off the vehicle axes, where
#: the forces of PowertrainMounts' mounts 4 to 8 are not zero and each component moves with every coordinate; and
#: one on snubbers (no rubber branches: Model Exchange takes it), whose modes move with the operating point's
#: g, T_mean and motor axis
TEST_POINTS = {"PowertrainMounts": ({**MODELS["PowertrainMounts"].dependency_points[0],
                                     "layout": str(Path(__file__).parent / "eight_mounts.toml")},
                                    {**MODELS["PowertrainMounts"].dependency_points[0],
                                     "layout": str(Path(__file__).parent / "snubbed_mounts.toml")})}


def points(model: str) -> list[dict[str, Any]]:
    return [{}, *MODELS[model].dependency_points, *TEST_POINTS.get(model, ())]
