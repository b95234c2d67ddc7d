"""What the studies' figures share: the resolution they are drawn and saved at, saving, and the
split of curves of very different sizes onto panels of their own scale, so that no curve is
drawn flat under a larger one."""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 120
WITHIN = 10.0  # a panel holds curves whose sizes lie within this factor of its largest


def figure(*args, **kwargs) -> tuple[plt.Figure, object]:
    """``plt.subplots`` at the resolution the figure is saved at, so that what a test measures
    on the figure in pixels is what the file shows."""
    return plt.subplots(*args, dpi=DPI, **kwargs)


def save(fig: plt.Figure, path: Path) -> Path:
    fig.savefig(path)
    plt.close(fig)
    return path


def by_scale(sizes: Mapping[Hashable, float], within: float = WITHIN) -> list[list[Hashable]]:
    """The keys of ``sizes`` (a curve's largest absolute value, say) in groups, largest first, each
    holding the curves within a factor ``within`` of its largest one."""
    groups: list[list[Hashable]] = []
    for key in sorted(sizes, key=lambda k: -sizes[k]):
        if groups and sizes[key] * within >= sizes[groups[-1][0]]:
            groups[-1].append(key)
        else:
            groups.append([key])
    return groups


def span(keys: list, unit: str = "deg") -> str:
    """``5 deg`` or ``5-15 deg`` for the sorted numeric ``keys`` of one panel."""
    low, high = min(keys), max(keys)
    return f"{low:g} {unit}" if low == high else f"{low:g}-{high:g} {unit}"
