"""What the studies' figures share: the resolution they are drawn and saved at, saving, the
colour-blind-safe palette, and the split of curves of very different sizes onto panels of their
own scale, so that no curve is drawn flat under a larger one."""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from cycler import cycler  # noqa: E402

DPI = 120
WITHIN = 10.0  # a panel holds curves whose sizes lie within this factor of its largest
#: The Okabe-Ito palette (Okabe and Ito, "Color Universal Design", 2008): its colours stay apart for the
#: common colour-vision deficiencies (no red against green); every curve of the studies takes one of
#: them, black or grey, or an evenly spaced colour of an ordered map (:func:`ordered`).
BLUE, ORANGE, GREEN, VERMILLION, PURPLE, SKY, YELLOW = (
    "#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442")
PALETTE = (BLUE, ORANGE, GREEN, VERMILLION, PURPLE, SKY, YELLOW, "#000000")
matplotlib.rcParams["axes.prop_cycle"] = cycler(color=PALETTE)


def ordered(count: int) -> list[tuple[float, float, float, float]]:
    """``count`` colours of viridis for an ordered series (bend angles, say), from dark to light, its
    brightest yellow left out so that every curve shows on white."""
    return [matplotlib.colormaps["viridis"](x) for x in np.linspace(0.0, 0.85, count)]


def figure(*args, **kwargs) -> tuple[plt.Figure, object]:
    """``plt.subplots`` at the resolution the figure is saved at, so that what a test measures
    on the figure in pixels is what the file shows."""
    return plt.subplots(*args, dpi=DPI, **kwargs)


def blank(**kwargs) -> plt.Figure:
    """An empty figure at the resolution it is saved at (for panels laid out by subfigures)."""
    return plt.figure(dpi=DPI, **kwargs)


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


def clear_of_lines(ax, annotation, placements: list[dict]) -> object:
    """Move ``annotation`` to the first of ``placements`` (its ``xy``, its offset ``xyann`` in points, its
    ``ha``) where no visible line of ``ax`` crosses its text, tested on the figure as it is drawn; the last
    when none is clear. Its box in data coordinates."""
    renderer = ax.figure.canvas.get_renderer()
    lines = [line for line in ax.get_lines() if line.get_visible() and line.get_linestyle() not in ("None", "")]
    for placement in placements:
        for name, value in placement.items():
            if name == "ha":
                annotation.set_horizontalalignment(value)
            else:
                setattr(annotation, name, value)
        box = annotation.get_window_extent(renderer).transformed(ax.transData.inverted())
        if not any(line.get_path().intersects_bbox(box, filled=False) for line in lines):
            break
    return box


def span(keys: list, unit: str = "deg") -> str:
    """``5 deg`` or ``5-15 deg`` for the sorted numeric ``keys`` of one panel."""
    low, high = min(keys), max(keys)
    return f"{low:g} {unit}" if low == high else f"{low:g}-{high:g} {unit}"
