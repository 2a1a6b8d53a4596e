"""One look for every figure randvib draws: style, layout, panel letters, and a layout check.

Studies, the identification plots and the response-spectra figure all draw
with it; it imports nothing of randvib's layers, so every layer may use it.
:func:`new_figure` makes a figure with constrained layout under :data:`STYLE`
(font sizes a journal accepts at column width, a colour-blind-safe cycle);
:func:`panel_letters` labels the panels (a), (b), (c)...;
:func:`text_overlaps` lists the pairs of texts (titles, axis labels, tick
labels, legends) that overlap once drawn, and :func:`legends_over_data` the
legends drawn over data points or lines, which :func:`save_figure` turns
into a :class:`FigureLayoutWarning` (an error in the tests) before it saves.
"""

from __future__ import annotations

import warnings
from contextlib import contextmanager
from itertools import combinations
from pathlib import Path

#: Okabe & Ito's colour-blind-safe palette (Nature Methods 8, 441, 2011), black last.
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")

#: Resolution of the saved PNG figures (dots per inch).
DPI = 200

#: The rcParams of every study figure.
STYLE = {
    "font.size": 9,
    "axes.titlesize": 9,
    "axes.labelsize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "legend.fontsize": 7,
    "legend.title_fontsize": 7,
    "figure.titlesize": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "lines.linewidth": 1.2,
    "lines.markersize": 4,
    "errorbar.capsize": 2,
    "savefig.dpi": DPI,
    "mathtext.default": "regular",
}


class FigureLayoutWarning(UserWarning):
    """A figure has no constrained layout, or two of its texts overlap."""


@contextmanager
def figure_style():
    """Context in which matplotlib draws with :data:`STYLE` and the :data:`PALETTE` cycle."""
    import matplotlib.pyplot as plt
    from cycler import cycler

    with plt.rc_context({**STYLE, "axes.prop_cycle": cycler(color=PALETTE)}):
        yield


def styled(func):
    """Decorator: draw the whole figure function under :func:`figure_style`.

    Titles, labels and legends take their sizes from the rcParams in force
    when they are made, so the style must hold while the function draws.
    """
    import functools

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with figure_style():
            return func(*args, **kwargs)

    return wrapper


def new_figure(nrows: int = 1, ncols: int = 1, **kwargs):
    """``plt.subplots`` under :data:`STYLE` with constrained layout; ``(fig, axes)``.

    ``squeeze`` defaults to False (``axes`` always 2-D). The style's sizes
    are fixed on the figure's artists when they are made, so drawing after
    the call keeps them.
    """
    import matplotlib.pyplot as plt

    kwargs.setdefault("squeeze", False)
    with figure_style():
        fig, axes = plt.subplots(nrows, ncols, layout="constrained", **kwargs)
    return fig, axes


def colour(i: int) -> str:
    """The ``i``-th colour of :data:`PALETTE` (cycling)."""
    return PALETTE[i % len(PALETTE)]


def num_tex(x: float) -> str:
    """``x`` for a label in mathtext: '0', '0.5', '5 × 10$^{5}$' (not '500000' or '5e+05')."""
    import math

    if x == 0 or 1e-3 <= abs(x) < 1e4:
        return f"{x:g}"
    exponent = math.floor(math.log10(abs(x)))
    mantissa = x / 10**exponent
    head = "" if round(mantissa, 3) == 1 else f"{mantissa:.3g} × "
    return f"{head}10$^{{{exponent}}}$"


def panel_letters(axes, *, start: int = 0) -> None:
    """Write (a), (b), (c)... at the top left, outside each of ``axes`` (row-major order)."""
    import numpy as np

    for i, ax in enumerate(np.ravel(axes)):
        ax.set_title(f"({chr(ord('a') + start + i)})", loc="left", fontweight="bold", fontsize=9)


def _texts(fig):
    """(owner, kind, text artist or legend) of every visible text of ``fig`` worth checking."""
    items = []
    for t in (fig._suptitle, fig._supxlabel, fig._supylabel):
        if t is not None and t.get_visible() and t.get_text():
            items.append(("figure", "suptitle", t))
    for leg in fig.legends:
        items.append(("figure", "legend", leg))
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        owner = id(ax)
        for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label):
            if t.get_visible() and t.get_text():
                items.append((owner, "label", t))
        for axis in (ax.xaxis, ax.yaxis):
            for t in _drawn_ticklabels(ax, axis):
                items.append((owner, f"tick{id(axis)}", t))
        leg = ax.get_legend()
        if leg is not None:
            items.append((owner, "legend", leg))
    return items


def _drawn_ticklabels(ax, axis):
    """The tick labels of ``axis`` that are drawn: visible, with text, inside the view limits."""
    import numpy as np

    # compare in the axis' scale (log10 on a log axis), where a relative slack is meaningful
    scale = axis.get_transform()
    lo, hi = sorted(np.ravel(scale.transform(np.reshape(axis.get_view_interval(), (-1, 1)))))
    slack = 1e-9 * (hi - lo)
    out = []
    for tick in axis.get_major_ticks() + axis.get_minor_ticks():
        loc = float(np.ravel(scale.transform([[tick.get_loc()]]))[0])
        if not lo - slack <= loc <= hi + slack:
            continue
        for t in (tick.label1, tick.label2):
            if t.get_visible() and t.get_text():
                out.append(t)
    return out


def text_overlaps(fig) -> list[str]:
    """The pairs of texts of ``fig`` that overlap once drawn, as 'A' / 'B' descriptions.

    Checked: titles, axis labels, tick labels (major and minor), the
    suptitle and legends, across all axes, tick labels of one axis against
    each other too (crowded log-axis labels). Not counted: a legend against
    the tick labels of its own axes (it sits inside them), and boxes that
    only touch (a pixel of slack).
    """
    fig.canvas.draw()
    return _text_overlaps(fig, fig.canvas.get_renderer())


def _text_overlaps(fig, renderer) -> list[str]:
    """:func:`text_overlaps` of a figure just drawn with ``renderer``."""
    boxes = []
    for owner, kind, artist in _texts(fig):
        box = artist.get_window_extent(renderer)
        if box.width > 0 and box.height > 0:
            boxes.append((owner, kind, artist, box))
    found = []
    for (o1, k1, a1, b1), (o2, k2, a2, b2) in combinations(boxes, 2):
        if o1 == o2 and "legend" in (k1, k2) and (k1 + k2).count("tick"):
            continue
        # a strictly positive overlap area, with a pixel of slack for touching boxes
        dx = min(b1.x1, b2.x1) - max(b1.x0, b2.x0)
        dy = min(b1.y1, b2.y1) - max(b1.y0, b2.y0)
        if dx > 1 and dy > 1:
            found.append(f"{_describe(a1)!r} / {_describe(a2)!r}")
    return found


def _describe(artist) -> str:
    return artist.get_text() if hasattr(artist, "get_text") else type(artist).__name__


def legends_over_data(fig) -> list[str]:
    """The legends of ``fig`` that cover data, as 'legend X over Y' descriptions.

    Data are the lines, markers, error bars and scatter points drawn in data
    coordinates of any axes (a twin's too), where they are inside their axes;
    reference lines in axes coordinates (``axhline``), shaded bands and texts
    are not counted. A line counts where a segment crosses the legend's
    frame, a marker where its centre lies inside it (less a pixel).
    """
    fig.canvas.draw()
    return _legends_over_data(fig, fig.canvas.get_renderer())


def _legends_over_data(fig, renderer) -> list[str]:
    """:func:`legends_over_data` of a figure just drawn with ``renderer``."""
    from matplotlib.collections import LineCollection, PathCollection
    from matplotlib.transforms import Bbox

    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    found = []
    for legend in legends:
        if not legend.get_visible():
            continue
        frame = legend.get_window_extent(renderer).padded(-1.0)
        for ax in fig.axes:
            region = Bbox.intersection(frame, ax.bbox) if ax.get_visible() else None
            if region is None or region.width <= 0 or region.height <= 0:
                continue
            for artist in (*ax.lines, *ax.collections):
                if not artist.get_visible() or not _in_data_coordinates(artist, ax):
                    continue
                if isinstance(artist, PathCollection):
                    hit = _points_inside(
                        artist.get_offset_transform(), artist.get_offsets(), region
                    )
                elif isinstance(artist, LineCollection):
                    hit = any(_crosses(artist.get_transform(), path.vertices, region)
                              for path in artist.get_paths())  # fmt: skip
                elif hasattr(artist, "get_xydata"):
                    hit = _line_over(artist, region)
                else:
                    continue
                if hit:
                    covered = _artist_name(artist, ax)
                    found.append(f"legend {_legend_name(legend)!r} over {covered!r}")
                    break
    return found


def _in_data_coordinates(artist, ax) -> bool:
    """Drawn in ``ax``'s data coordinates (not an axes-fraction reference line)."""
    transform = artist.get_transform()
    return transform.contains_branch(ax.transData) or (
        hasattr(artist, "get_offset_transform")
        and artist.get_offset_transform().contains_branch(ax.transData)
    )


def _line_over(line, region) -> bool:
    """A Line2D's segments cross ``region``, or one of its markers lies inside it."""
    xy = line.get_xydata()
    if len(xy) == 0:
        return False
    drawn = line.get_linestyle() not in ("None", "none", "", " ")
    if drawn and len(xy) > 1 and _crosses(line.get_transform(), xy, region):
        return True
    return line.get_marker() not in ("None", "none", "", " ", None) and _points_inside(
        line.get_transform(), xy, region
    )


def _points_inside(transform, xy, region) -> bool:
    import numpy as np

    points = transform.transform(np.asarray(xy, dtype=float))
    points = points[np.all(np.isfinite(points), axis=1)]
    inside = (
        (points[:, 0] >= region.x0)
        & (points[:, 0] <= region.x1)
        & (points[:, 1] >= region.y0)
        & (points[:, 1] <= region.y1)
    )
    return bool(np.any(inside))


def _crosses(transform, xy, region) -> bool:
    """Whether the polyline ``xy`` (in ``transform``'s coordinates) enters ``region``."""
    import numpy as np
    from matplotlib.path import Path as MplPath

    points = transform.transform(np.asarray(xy, dtype=float))
    keep = np.all(np.isfinite(points), axis=1)
    if keep.sum() < 2:
        return _points_inside(transform, np.asarray(xy)[keep], region) if keep.any() else False
    return bool(MplPath(points[keep]).intersects_bbox(region, filled=False)) or _points_inside(
        transform, np.asarray(xy, dtype=float)[keep], region
    )


def _legend_name(legend) -> str:
    """A legend by its title, else its entries."""
    title = legend.get_title().get_text()
    texts = ", ".join(t.get_text() for t in legend.get_texts())
    return title or texts or "legend"


def _artist_name(artist, ax) -> str:
    """An artist by its label, or by its container's (an error bar's line and bars)."""
    for container in ax.containers:
        if artist in container.get_children() and not container.get_label().startswith("_"):
            return container.get_label()
    label = artist.get_label()
    return label if label and not label.startswith("_") else type(artist).__name__


def check_layout(fig, name: str) -> None:
    """Warn (:class:`FigureLayoutWarning`) if ``fig`` lacks constrained layout, texts overlap
    or a legend covers data (:func:`legends_over_data`)."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    if not isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine):
        warnings.warn(f"figure {name}: no constrained layout", FigureLayoutWarning, stacklevel=3)
    # one draw for both checks (a draw with constrained layout is most of their time),
    # without rasterising: the checks need the solved layout and the texts' extents,
    # not pixels (save_figure rasterises once, at its DPI)
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    overlaps = _text_overlaps(fig, renderer)
    if overlaps:
        warnings.warn(
            f"figure {name}: overlapping texts: " + "; ".join(overlaps),
            FigureLayoutWarning,
            stacklevel=3,
        )
    covered = _legends_over_data(fig, renderer)
    if covered:
        warnings.warn(
            f"figure {name}: legend over data: " + "; ".join(covered),
            FigureLayoutWarning,
            stacklevel=3,
        )


def save_figure(fig, path, *, tracked: bool = True) -> Path:
    """Save ``fig`` as a PNG (:data:`DPI`) and close it; returns the path.

    Before saving, :func:`check_layout` warns if the figure lacks constrained
    layout or two of its texts overlap. In a result folder (``tracked``, the
    default) an edited PNG is not replaced (:func:`randvib._io.write_tracked`);
    a path the user named (``--plot``), already checked by its command, is
    simply written.
    """
    import io

    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    from randvib._io import atomic_write_bytes, write_tracked

    path = Path(path)
    check_layout(fig, path.name)
    if isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine):
        # the check's draw solved the layout (axes positions in figure fractions, the same
        # at any dpi): the PNG keeps what was checked, without solving it again (the
        # solve was most of a saved figure's time)
        fig.set_layout_engine("none")
    buffer = io.BytesIO()
    if isinstance(fig.canvas, FigureCanvasAgg):
        # what savefig(dpi=DPI) writes, byte for byte, less its extra (non-rasterising)
        # draw before printing, which only a layout engine or a tight bounding box needs
        fig.dpi = DPI
        fig.canvas.print_png(buffer)
    else:  # a figure of a non-Agg backend (MPLBACKEND=pdf): let savefig switch canvas
        fig.savefig(buffer, format="png", dpi=DPI)
    plt.close(fig)
    if not tracked:
        atomic_write_bytes(path, buffer.getvalue())
        return path
    return write_tracked(path, buffer.getvalue())
