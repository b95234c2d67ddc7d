"""What a matplotlib figure draws, measured on its artists in display pixels, for the tests of the
main job's figures: a curve hidden under the curves drawn over it, markers stacked so that one
hides the other, data beyond the axes' limits, a log axis over a zero, one legend per figure.

A curve is *seen* at a sample when no curve drawn over it (a higher z-order, or the same and
later) passes within half their two line widths plus :data:`CLEAR_PX` of it there, and it is
*hidden* when it is seen at fewer than :data:`SEEN_SHARE` of its samples. A solid curve is seen
between the dashes of a dashed or dotted curve of another colour drawn over it. Two markers that
overlap must *nest*: the one beneath a ring (no fill) at least :data:`NEST_PX` larger than the
one on top, or the one on top a ring at least as much larger than the one beneath.
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

CLEAR_PX = 0.5  # clear space between two lines' edges for the one beneath to be seen [px]
SEEN_SHARE = 0.5  # share of its samples at which a curve must be seen
NEST_PX = 3.0  # how much larger the outer of two overlapping markers must be [px]


def _drawn(fig: Figure) -> list[Axes]:
    fig.canvas.draw()
    return fig.axes


def _order(ax: Axes, artists: list[Line2D]) -> list[Line2D]:
    """``artists`` in the order they are drawn (z-order, then the order added)."""
    position = {id(artist): k for k, artist in enumerate(ax.get_children())}
    return sorted(artists, key=lambda a: (a.get_zorder(), position[id(a)]))


def _pixels(line: Line2D) -> np.ndarray:
    x, y = (np.asarray(v, dtype=float) for v in line.get_data())
    points = line.get_transform().transform(np.column_stack([x, y]))
    return points[np.all(np.isfinite(points), axis=1)]


def _points(line: Line2D, value: float) -> float:
    return value * line.figure.dpi / 72.0


def _distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Each point's distance [px] to the nearest segment of ``polyline``."""
    if len(polyline) == 1:
        return np.linalg.norm(points - polyline[0], axis=1)
    start, end = polyline[:-1], polyline[1:]
    span = end - start
    length = np.maximum((span ** 2).sum(axis=1), 1e-12)
    t = np.clip(((points[:, None, :] - start[None]) * span[None]).sum(axis=2) / length[None], 0.0, 1.0)
    nearest = start[None] + t[..., None] * span[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def _curves(ax: Axes) -> list[Line2D]:
    return [line for line in ax.get_lines() if line.get_visible() and line.get_linestyle() not in ("None", "")
            and len(_pixels(line)) > 1]


def seen_share(ax: Axes, line: Line2D) -> float:
    """Share of ``line``'s samples at which no curve drawn over it lies on it."""
    order = _order(ax, _curves(ax))
    points = _pixels(line)
    covered = np.zeros(len(points), dtype=bool)
    for above in order[order.index(line) + 1:]:
        solid_beneath = line.get_linestyle() == "-"
        if solid_beneath and above.get_linestyle() != "-" and to_rgba(above.get_color()) != to_rgba(line.get_color()):
            continue
        width = (_points(line, line.get_linewidth()) + _points(above, above.get_linewidth())) / 2 + CLEAR_PX
        covered |= _distance_to_polyline(points, _pixels(above)) < width
    return float(1.0 - covered.mean())


def hidden_curves(fig: Figure) -> list[str]:
    """``axes title: curve label`` of every curve seen at fewer than SEEN_SHARE of its samples."""
    return [f"{ax.get_title()}: {line.get_label()}" for ax in _drawn(fig) for line in _curves(ax)
            if seen_share(ax, line) < SEEN_SHARE]


def _markers(ax: Axes) -> list[tuple[Line2D, np.ndarray]]:
    return [(line, point) for line in _order(ax, list(ax.get_lines()))
            if line.get_visible() and line.get_marker() not in ("None", "", None)
            for point in _pixels(line)]


def _ring(line: Line2D) -> bool:
    return line.get_markerfacecolor() == "none" or line.get_marker() not in Line2D.filled_markers


def stacked_markers(fig: Figure) -> list[str]:
    """Pairs of overlapping markers of two artists that do not nest (see the module's docstring)."""
    found = []
    for ax in _drawn(fig):
        markers = _markers(ax)
        for k, (below, p) in enumerate(markers):
            for above, q in markers[k + 1:]:
                if above is below:
                    continue
                size_below, size_above = _points(below, below.get_markersize()), _points(above, above.get_markersize())
                if np.linalg.norm(p - q) >= (size_below + size_above) / 2:
                    continue
                nested = (_ring(below) and size_below >= size_above + NEST_PX) or (
                    _ring(above) and size_above >= size_below + NEST_PX)
                if not nested:
                    found.append(f"{ax.get_title()}: {below.get_label()} under {above.get_label()} at {p.round()}")
    return found


def beyond_limits(fig: Figure) -> list[str]:
    """Curves and markers with a finite sample outside their axes' limits."""
    found = []
    for ax in _drawn(fig):
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        for line in ax.get_lines():
            x, y = (np.asarray(v, dtype=float) for v in line.get_data())
            inside = np.isfinite(x) & np.isfinite(y)
            if line.get_visible() and np.any((x[inside] < x0) | (x[inside] > x1) | (y[inside] < y0) | (y[inside] > y1)):
                found.append(f"{ax.get_title()}: {line.get_label()}")
    return found


def log_over_zero(fig: Figure) -> list[str]:
    """Curves on a log axis with a sample at or below zero, or more than 12 decades under the axis's
    largest value: a numerical zero plotted as if it were a value."""
    found = []
    for ax in _drawn(fig):
        if ax.get_yscale() != "log":
            continue
        lines = [line for line in ax.get_lines() if len(line.get_ydata())]
        top = max(float(np.nanmax(line.get_ydata())) for line in lines)
        for line in lines:
            y = np.asarray(line.get_ydata(), dtype=float)
            if np.any(y[np.isfinite(y)] <= top * 1e-12):
                found.append(f"{ax.get_title()}: {line.get_label()}")
    return found


def _legends(fig: Figure) -> list:
    return [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend() is not None)]


def legend_count(fig: Figure) -> int:
    return len(_legends(fig))


def repeated_legends(fig: Figure) -> list[list[str]]:
    """The entries of every legend that repeats another one of the figure."""
    entries = [[text.get_text() for text in legend.get_texts()] for legend in _legends(fig)]
    return [labels for k, labels in enumerate(entries) if labels in entries[:k]]


def empty_axes(fig: Figure) -> list[str]:
    """Visible axes that draw nothing: no line, collection, image or patch with data."""
    return [ax.get_title() or f"axes {k}" for k, ax in enumerate(_drawn(fig)) if ax.get_visible() and not ax.has_data()]


def texts_outside_canvas(fig: Figure) -> list[str]:
    """Axes whose drawn texts (title, axis labels, tick labels, annotations, legend) and the figure's own
    texts and legends that reach beyond the figure's edges, cut off in the saved file (by more than half
    a pixel)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    width, height = fig.canvas.get_width_height()
    boxes = [(ax.get_title() or ax.get_ylabel() or "axes", ax.get_tightbbox(renderer)) for ax in fig.axes
             if ax.get_visible()]
    texts = [*fig.texts, *([fig._suptitle] if getattr(fig, "_suptitle", None) is not None else [])]
    boxes += [(text.get_text(), text.get_window_extent(renderer)) for text in texts if text.get_text().strip()]
    boxes += [("figure legend", legend.get_window_extent(renderer)) for legend in fig.legends]
    return [name for name, box in boxes
            if box.x0 < -0.5 or box.y0 < -0.5 or box.x1 > width + 0.5 or box.y1 > height + 0.5]


def texts_on_lines(fig: Figure) -> list[str]:
    """Annotations and texts written inside an axes that a visible curve of the axes crosses (the curve
    sampled every pixel along its polyline, the text's box shrunk by a pixel)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        curves = [_dense(_pixels(line)) for line in _curves(ax)]
        for text in ax.texts:
            if not (text.get_visible() and text.get_text().strip()):
                continue
            box = text.get_window_extent(renderer).expanded(1.0, 1.0)
            x0, y0, x1, y1 = box.x0 + 1, box.y0 + 1, box.x1 - 1, box.y1 - 1
            for points in curves:
                if np.any((points[:, 0] > x0) & (points[:, 0] < x1) & (points[:, 1] > y0) & (points[:, 1] < y1)):
                    found.append(f"{ax.get_title()}: {text.get_text()}")
                    break
    return found


def _dense(points: np.ndarray) -> np.ndarray:
    """The polyline through ``points`` sampled at least every pixel."""
    if len(points) < 2:
        return points
    pieces = [points[:1]]
    for start, end in zip(points[:-1], points[1:]):
        count = max(1, int(np.ceil(np.linalg.norm(end - start))))
        pieces.append(start + np.outer(np.arange(1, count + 1) / count, end - start))
    return np.vstack(pieces)


#: Colours a figure may draw its curves and markers in: the Okabe-Ito palette (safe for the common
#: colour-vision deficiencies), black, white and greys; a colour map's colours (viridis, cividis,
#: magma: perceptually ordered, readable without hue) are images and collections, not lines.
SAFE_COLOURS = ("#0072b2", "#e69f00", "#009e73", "#d55e00", "#cc79a7", "#56b4e9", "#f0e442", "#000000", "#ffffff")


def _safe(colour) -> bool:
    red, green, blue, _ = to_rgba(colour)
    grey = abs(red - green) < 1e-6 and abs(green - blue) < 1e-6
    return grey or any(np.allclose((red, green, blue), to_rgba(safe)[:3], atol=2e-3) for safe in SAFE_COLOURS)


def unsafe_colours(fig: Figure, ordered: tuple[str, ...] = ("viridis", "cividis")) -> list[str]:
    """Curves and markers drawn in a colour outside :data:`SAFE_COLOURS` and the ``ordered`` colour maps
    (a series of bend angles, say, coloured by a map's evenly spaced colours)."""
    import matplotlib

    maps = [matplotlib.colormaps[name] for name in ordered]
    samples = np.vstack([cmap(np.linspace(0.0, 1.0, 1025))[:, :3] for cmap in maps])

    def allowed(colour) -> bool:
        if colour in ("none", "None") or to_rgba(colour)[3] == 0.0:
            return True
        rgb = np.array(to_rgba(colour)[:3])
        return _safe(colour) or bool(np.any(np.abs(samples - rgb).max(axis=1) < 2e-3))

    found = []
    for ax in _drawn(fig):
        for line in ax.get_lines():
            if not line.get_visible():
                continue
            colours = [line.get_color()] + ([line.get_markerfacecolor(), line.get_markeredgecolor()]
                                            if line.get_marker() not in ("None", "", None) else [])
            found += [f"{ax.get_title()}: {line.get_label()} in {colour}" for colour in colours if not allowed(colour)]
    return found
