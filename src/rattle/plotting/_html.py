"""Interactive pages: one self-contained HTML file per result, drawn with plotly.

:func:`frequency_response_html`, :func:`compare_html` and :func:`map_html` return the text of an
HTML document that holds plotly.js itself (plotly's ``include_plotlyjs=True`` bundle: no network,
no CDN), the figure as JSON (``<script type="application/json" id="rattle-figure">``, read by
the page's last script and by tests), and the result's summary (``<pre id="rattle-summary">``).

Every point carries its hover text: Ω (and the crankshaft rpm, n = Ω · 60 / (2π q_0), for a
model with an engine), the quantity drawn, stable or unstable, the period p of its orbit (the
orbit repeats after p forcing periods), its branch, and the special point or region it marks.
What is drawn follows the PNG figures of :mod:`rattle.plotting`:

- a smooth law: every branch, stable solid, unstable dashed (one panel per clearance element of
  a chain), the special points, the regions shaded and labelled, the linear system in grey;
- a law with jumps or friction (``frf.check`` set): the exact shooting rows of every branch
  (period-1 and the sub-harmonic ones), stable solid, unstable dashed, rows the shooting did not
  match left out, the regularised harmonic balance thin grey, the rows where the stability or
  the switching pattern changes marked;
- a comparison: the frequency response with the up (▲) and down (▼) sweep points over it and the
  examined frequencies (a), (b)…, with δ(t) of the orbits there below;
- a response map: the heat map of the largest stable rms (or sound pressure level), grey where
  there is no stable period-1 solution, impacting cells marked ×, the rattle-free cells outlined;
  with two or more varied parameters a menu chooses the combination of the others.

plotly is an optional dependency (``pip install "rattle[html]"``), imported inside the
functions: importing this module costs nothing.
"""

from __future__ import annotations

import html
import importlib.util
import json
import math
import string
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["frequency_response_html", "compare_html", "map_html", "plotly_available", "PLOTLY_MISSING"]

#: What to say when plotly is not installed.
PLOTLY_MISSING = 'the interactive page needs plotly: pip install "rattle[html]"'

#: Colours of the branches (plotly's default sequence, as matplotlib's tab10).
_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
            "#17becf")
#: Marker symbol of each kind of special point (the PNG's ○ □ ◇, and the exact rows' grazings).
_SPECIAL_SYMBOLS = {"fold": "circle-open", "period_doubling": "square-open", "neimark_sacker": "diamond-open",
                    "grazing": "triangle-up-open", "grazing_sliding": "triangle-down-open"}
_REGION_FILL = {"subharmonic": "rgba(245,195,66,0.22)", "unstable_period_doubling": "rgba(148,103,189,0.12)",
                "unstable_not_computed": "rgba(127,127,127,0.12)", "no_stable_computed": "rgba(127,127,127,0.18)",
                "no_stable_periodic": "rgba(100,100,100,0.25)", "torus": "rgba(44,160,44,0.12)"}
_GREY = "#8c8c8c"
#: Pixel height of one response panel and of one row of time histories.
_PANEL_HEIGHT = 430
_HISTORY_HEIGHT = 300


def plotly_available() -> bool:
    """True when plotly can be imported (looked up, not imported: cheap)."""
    return importlib.util.find_spec("plotly") is not None


def _require_plotly() -> None:
    if not plotly_available():
        raise ImportError(PLOTLY_MISSING)


# --------------------------------------------------------------------------------------------
# The page
# --------------------------------------------------------------------------------------------
def _jsonable(obj: Any) -> Any:
    """``obj`` with numpy arrays and scalars as lists and numbers, NaN and ±inf as null."""
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(float(obj)) else None
    return obj


def _page(fig: Any, title: str, summary: str | None) -> str:
    """The HTML document: plotly.js inline, the figure as JSON, the summary below the plot."""
    from plotly.offline import get_plotlyjs

    from .. import __version__

    height = int(fig.layout.height or 500)
    figure = json.dumps(_jsonable(fig.to_plotly_json()), allow_nan=False, ensure_ascii=False, separators=(",", ":"))
    figure = figure.replace("</", "<\\/")  # a "</script>" in a label must not end the script
    summary_block = "" if not summary else (
        f'<h2>Summary</h2>\n<pre id="rattle-summary">{html.escape(summary)}</pre>\n')
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{html.escape(title)}</title>\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        "<style>body{font-family:system-ui,sans-serif;margin:1em 2em;color:#222}"
        "h1{font-size:1.3em}h2{font-size:1.1em}"
        f"#rattle-plot{{width:100%;height:{height}px}}"
        "pre{background:#f6f6f6;padding:.8em;white-space:pre-wrap;font-size:.85em}"
        "footer{color:#888;font-size:.8em;margin-top:1em}</style>\n"
        f"<script type=\"text/javascript\">{get_plotlyjs()}</script>\n</head>\n<body>\n"
        f"<h1>{html.escape(title)}</h1>\n<div id=\"rattle-plot\"></div>\n{summary_block}"
        f"<footer>rattle {html.escape(str(__version__))}: hover over a curve for its values; drag to zoom, "
        "double-click to reset; click a legend entry to hide it.</footer>\n"
        f"<script type=\"application/json\" id=\"rattle-figure\">{figure}</script>\n"
        "<script type=\"text/javascript\">(function () {\n"
        "  var f = JSON.parse(document.getElementById(\"rattle-figure\").textContent);\n"
        "  Plotly.newPlot(\"rattle-plot\", f.data, f.layout, {responsive: true, displaylogo: false});\n"
        "})();</script>\n</body>\n</html>\n"
    )


# --------------------------------------------------------------------------------------------
# Pieces
# --------------------------------------------------------------------------------------------
def _engine(result: Any) -> float | None:
    """rpm per rad/s of a result whose model has an engine (60 / (2π q_0)); None without one."""
    order = getattr(getattr(result, "model", None), "speed_order", None)
    return None if order is None else 60.0 / (2.0 * np.pi * float(order))


def _x_title(rpm: float | None) -> str:
    return "forcing frequency Ω (rad/s)" if rpm is None else "engine speed (rpm)"


def _where(omega: float, rpm: float | None) -> str:
    return f"Ω = {omega:.6g} rad/s" + ("" if rpm is None else f" ({omega * rpm:.6g} rpm)")


def _num(v: float, unit: str = "") -> str:
    return "—" if not math.isfinite(float(v)) else f"{float(v):.5g}{unit}"


def _pieces(x: np.ndarray, y: np.ndarray, text: Sequence[str], mask: np.ndarray) -> tuple[list, list, list]:
    """The runs of consecutive True in ``mask``, each extended by one point (so that solid and
    dashed pieces join), joined by gaps (None)."""
    from ._frf import true_runs

    xs: list[Any] = []
    ys: list[Any] = []
    ts: list[Any] = []
    for i0, i1 in true_runs(np.asarray(mask, dtype=bool)):
        j1 = min(int(i1) + 1, x.size)
        xs += [*x[i0:j1].tolist(), None]
        ys += [*y[i0:j1].tolist(), None]
        ts += [*text[i0:j1], ""]
    return xs, ys, ts


def _line(go: Any, x: list, y: list, text: list, *, name: str, colour: str, dash: str, width: float,
          group: str, legend: bool) -> Any:
    return go.Scatter(x=x, y=y, hovertext=text, hovertemplate="%{hovertext}<extra></extra>", mode="lines",
                      name=name, legendgroup=group, showlegend=legend, connectgaps=False,
                      line={"color": colour, "dash": dash, "width": width})


def _curve(go: Any, x: np.ndarray, y: np.ndarray, text: Sequence[str], stable: np.ndarray, shown: np.ndarray, *,
           name: str, colour: str, legend: bool, width: float = 2.0) -> list[Any]:
    """A branch: stable rows solid, unstable dashed (the rows not ``shown`` left out)."""
    traces = []
    for flag, dash, word in ((True, "solid", "stable"), (False, "dash", "unstable")):
        sel = shown & (stable == flag)
        if not np.any(sel):
            continue
        xs, ys, ts = _pieces(x, y, text, sel)
        traces.append(_line(go, xs, ys, ts, name=f"{name}, {word}", colour=colour, dash=dash,
                            width=width if flag else 0.8 * width, group=f"{name}, {word}", legend=legend))
    return traces


def _markers(go: Any, x: Sequence[float], y: Sequence[float], text: Sequence[str], *, name: str, symbol: str,
             colour: str, legend: bool, size: float = 10) -> Any:
    return go.Scatter(x=list(x), y=list(y), hovertext=list(text), hovertemplate="%{hovertext}<extra></extra>",
                      mode="markers", name=name, legendgroup=name, showlegend=legend,
                      marker={"symbol": symbol, "color": colour, "size": size, "line": {"width": 2, "color": colour}})


def _region_text(region: Any) -> str:
    """The short label of a region's band (the PNG's: ``period 2``, ``period 2 likely``, ``P1 unstable``…)."""
    from ._frf import UNSTABLE_REGION_STYLES

    if region.kind == "subharmonic":
        return f"period {int(region.detail.get('period', 2))}"
    if region.kind == "torus":
        return "torus"
    if region.kind == "unstable_period_doubling":
        return f"period {2 * int(region.detail.get('period', 1))} likely"
    return UNSTABLE_REGION_STYLES[region.kind][3].replace("\n", " ")


def _regions(fig: Any, frf: Any, scale: float, rows: int) -> None:
    """The named regions and the uncovered parts of the range as labelled vertical bands."""
    for a, b in getattr(frf, "uncovered", None) or []:
        fig.add_vrect(x0=a * scale, x1=b * scale, fillcolor="rgba(200,200,200,0.5)", line_width=0, layer="below",
                      row="all", col=1, label={"text": "not covered", "textposition": "top center",
                                               "font": {"size": 10}})
    for r in getattr(frf, "regions", ()) or ():
        if r.kind == "superharmonic" or r.kind not in _REGION_FILL:
            continue
        text = _region_text(r)
        fig.add_vrect(x0=r.omega_min * scale, x1=r.omega_max * scale, fillcolor=_REGION_FILL[r.kind], line_width=0,
                      layer="below", row="all", col=1,
                      label={"text": text[:40], "textposition": "top center", "font": {"size": 10}})


# --------------------------------------------------------------------------------------------
# Frequency response
# --------------------------------------------------------------------------------------------
#: Labels of the quantities a page can draw (the PNG's, with the sound pressure level).
def _label(quantity: str) -> str:
    from ._frf import QUANTITY_LABELS

    extra = {"spl_db": "sound pressure level (dB re 20 µPa)", "spl_dba": "A-weighted sound pressure level (dB(A))"}
    return QUANTITY_LABELS.get(quantity, extra.get(quantity, quantity))


def _unit(quantity: str) -> str:
    return " dB" if quantity.startswith("spl") else (" rad/s²" if quantity == "acc_p2p" else " rad")


def _hb_panels(frf: Any, quantity: str) -> list[tuple[str, str, int]]:
    """(column, panel title, element index) of each panel of a smooth law's response."""
    names = tuple(getattr(frf, "element_names", ()) or ())
    sound = "spl_db" in (getattr(frf, "extra_columns", {}) or {})
    if quantity.startswith("spl"):
        return [(quantity, _label(quantity), 0)]
    suffix = {"delta_min": "min", "delta_max": "max"}.get(quantity, quantity)
    panels = [(f"{n}_{suffix}", f"element {n}: {_label(quantity)}", k) for k, n in enumerate(names)] or \
        [(quantity, _label(quantity), 0)]
    if sound:
        panels.append(("spl_db", _label("spl_db"), 0))
    return panels


def _hb_traces(go: Any, fig: Any, frf: Any, key: str, quantity: str, element: int, row: int, *,
               linear: bool, first: bool) -> None:
    """One panel of a smooth law's response: every branch, the special points, the linear system."""
    from ._frf import column

    rpm = _engine(frf)
    scale = rpm or 1.0
    omega = np.asarray(frf.omega, dtype=float)
    x = omega * scale
    y = column(frf, key)
    stable = np.asarray(frf.stable, dtype=bool)
    period = np.asarray(frf.period, dtype=int)
    branch = np.asarray(frf.branch, dtype=int)
    regime = np.asarray(frf.regime, dtype=object)
    special = {int(sp.index): sp for sp in frf.special_points}
    unit = _unit(quantity)
    text = [
        f"{_where(omega[i], rpm)}<br>{key} = {_num(y[i], unit)}<br>{'stable' if stable[i] else 'unstable'}, "
        f"period {period[i]}, branch {branch[i]}" + (f"<br>regime {regime[i]}" if regime[i] else "")
        + (f"<br><b>{special[i].kind.replace('_', ' ')}</b>" if i in special else "")
        for i in range(omega.size)
    ]
    for n, b in enumerate(np.unique(branch)):
        sel = branch == b
        p = int(period[sel][0])
        name = f"branch {b}" + (f" (period {p})" if p > 1 else "")
        for tr in _curve(go, x[sel], y[sel], [t for t, s in zip(text, sel) if s], stable[sel], np.ones(sel.sum(), bool),
                         name=name, colour=_COLOURS[n % len(_COLOURS)], legend=first):
            fig.add_trace(tr, row=row, col=1)
    kinds: dict[str, list[int]] = {}
    for i, sp in special.items():
        kinds.setdefault(sp.kind, []).append(i)
    for kind, idx in kinds.items():
        fig.add_trace(_markers(go, x[idx], y[idx], [text[i] for i in idx], name=kind.replace("_", " "),
                               symbol=_SPECIAL_SYMBOLS.get(kind, "x"), colour="#d62728", legend=first), row=row, col=1)
    if linear and quantity in ("mean", "rms", "rms_ac") and key != "spl_db":
        lin = frf.linear_response(element=element)
        yl = np.asarray(getattr(lin, quantity), dtype=float)
        lt = [f"linear system (f = δ)<br>{_where(w, rpm)}<br>{quantity} = {_num(v, ' rad')}" for w, v in zip(lin.omega, yl)]
        fig.add_trace(go.Scatter(x=(np.asarray(lin.omega) * scale).tolist(), y=yl.tolist(), hovertext=lt,
                                 hovertemplate="%{hovertext}<extra></extra>", mode="lines", name="linear system (f = δ)",
                                 legendgroup="linear", showlegend=first, line={"color": _GREY, "width": 1}),
                      row=row, col=1)
    if key == "spl_db" and "spl_linear_db" in frf.extra_columns:
        order = np.argsort(omega, kind="stable")
        yl = np.asarray(frf.extra_columns["spl_linear_db"], dtype=float)[order]
        fig.add_trace(go.Scatter(x=x[order].tolist(), y=yl.tolist(), mode="lines", name="linear system (f = δ)",
                                 legendgroup="linear", showlegend=False, hoverinfo="skip",
                                 line={"color": _GREY, "width": 1}), row=row, col=1)


def _check_parts(frf: Any) -> tuple[Any, ...]:
    check = frf.check
    return (check, *check.branches)


def _check_panels(frf: Any, quantity: str) -> list[tuple[str, str, int]]:
    names = tuple(getattr(frf.check, "element_names", ()) or ())
    if names:
        if quantity not in ("rms", "mean"):
            raise ValueError(f"`quantity` of a chain with friction or jumps must be rms or mean (its exact rows "
                             f"carry those per element), got {quantity!r}")
        return [(quantity, f"element {n}: {_label(quantity)}", k) for k, n in enumerate(names)]
    if quantity not in ("mean", "rms", "rms_ac", "p2p", "acc_p2p"):
        raise ValueError(f"`quantity` of a law with jumps or friction must be one of mean, rms, rms_ac, p2p, "
                         f"acc_p2p, got {quantity!r}")
    return [(quantity, _label(quantity), 0)]


def _check_traces(go: Any, fig: Any, frf: Any, quantity: str, element: int, row: int, *, first: bool,
                  hb: bool = True) -> None:
    """One panel of a law with jumps or friction: the exact rows of every branch (and the
    regularised HB's rms), the changes of stability and of the switching pattern marked."""
    rpm = _engine(frf)
    scale = rpm or 1.0
    unit = _unit(quantity)
    marks: dict[str, tuple[list, list, list]] = {}
    for n, part in enumerate(_check_parts(frf)):
        w = np.asarray(part.omega, dtype=float)
        x = w * scale
        y = np.asarray(getattr(part, quantity), dtype=float)
        y = y.reshape(len(w), -1)[:, element] if y.ndim == 2 else y
        matched = np.asarray(part.matched, dtype=bool)
        stable = np.asarray(part.stable, dtype=bool)
        stick = np.asarray(part.stick_fraction, dtype=float)
        stick = stick.reshape(len(w), -1)[:, element] if stick.ndim == 2 else stick
        label = np.asarray(part.bifurcation, dtype=object)
        text = [
            f"{_where(w[i], rpm)}<br>{quantity} = {_num(y[i], unit)} (exact orbit)<br>"
            f"{'stable' if stable[i] else 'unstable'}, period {part.period}, branch {part.branch}"
            + (f"<br>held {stick[i]:.3g} of the period" if math.isfinite(stick[i]) and stick[i] > 0 else "")
            + (f"<br><b>{str(label[i]).replace('_', ' ')}</b>" if label[i] else "")
            for i in range(w.size)
        ]
        name = "exact, period 1" if part.period == 1 and n == 0 else f"branch {part.branch} (period {part.period}), exact"
        colour = _COLOURS[n % len(_COLOURS)]
        for tr in _curve(go, x, y, text, stable, matched & np.isfinite(y), name=name, colour=colour, legend=first):
            fig.add_trace(tr, row=row, col=1)
        rms_hb = np.asarray(part.rms_hb, dtype=float)
        rms_hb = rms_hb.reshape(len(w), -1)[:, element] if rms_hb.ndim == 2 else rms_hb
        if hb and quantity == "rms" and np.any(np.isfinite(rms_hb)):
            ht = [f"regularised HB (ε = {part.regularisation:g}, H = {part.harmonics})<br>{_where(wi, rpm)}<br>"
                  f"rms = {_num(v, ' rad')}" for wi, v in zip(w, rms_hb)]
            fig.add_trace(go.Scatter(x=x.tolist(), y=[None if not math.isfinite(v) else v for v in rms_hb.tolist()],
                                     hovertext=ht, hovertemplate="%{hovertext}<extra></extra>", mode="lines",
                                     name=f"regularised HB (H = {part.harmonics}, ε = {part.regularisation:g})",
                                     legendgroup="hb", showlegend=first and n == 0,
                                     line={"color": _GREY, "width": 1}), row=row, col=1)
        for i in np.flatnonzero(label != ""):
            if np.isfinite(y[i]):
                m = marks.setdefault(str(label[i]), ([], [], []))
                m[0].append(float(x[i]))
                m[1].append(float(y[i]))
                m[2].append(text[i])
    for kind, (xs, ys, ts) in marks.items():
        fig.add_trace(_markers(go, xs, ys, ts, name=kind.replace("_", " "), symbol=_SPECIAL_SYMBOLS.get(kind, "x"),
                               colour="#d62728", legend=first), row=row, col=1)


def _frf_title(frf: Any) -> str:
    if frf.check is not None:
        return f"Frequency response ({frf.check.followed}, checked by exact shooting)" \
            if frf.check.followed != "exact shooting" else "Frequency response (exact shooting)"
    return f"Non-linear frequency response (H = {frf.harmonics_text()})"


def _layout(fig: Any, height: int, rpm: float | None, rows: int) -> None:
    fig.update_layout(height=height, hovermode="closest", template="plotly_white", legend={"font": {"size": 11}},
                      margin={"l": 70, "r": 20, "t": 40, "b": 55})
    fig.update_xaxes(showgrid=True, zeroline=False)
    fig.update_yaxes(showgrid=True, zeroline=False)
    fig.update_xaxes(title_text=_x_title(rpm), row=rows, col=1)


def _frf_figure(frf: Any, *, quantity: str = "rms", title: str | None = None) -> Any:
    """The plotly Figure of ``frf``: see :func:`frequency_response_html`."""
    _require_plotly()
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    if not isinstance(quantity, str):
        raise TypeError(f"`quantity` must be a column name (str), got {quantity!r}")
    if frf.check is None:
        from ._frf import QUANTITY_LABELS

        sound = [k for k in ("spl_db", "spl_dba") if k in (getattr(frf, "extra_columns", {}) or {})]
        known = [k for k in QUANTITY_LABELS if not k.startswith("spl")]  # the levels only with sound paths
        if quantity not in known and quantity not in sound:
            raise ValueError(f"`quantity` must be one of {', '.join([*known, *sound])} (spl_db and spl_dba "
                             f"with sound paths: FrequencyResponse.with_sound), got {quantity!r}")
    panels = _check_panels(frf, quantity) if frf.check is not None else _hb_panels(frf, quantity)
    rows = len(panels)
    fig = make_subplots(rows=rows, cols=1, shared_xaxes=True, vertical_spacing=0.06 if rows > 1 else 0.0,
                        subplot_titles=[t for _, t, _ in panels] if rows > 1 else None)
    for r, (key, panel_title, element) in enumerate(panels, start=1):
        if frf.check is not None:
            _check_traces(go, fig, frf, key, element, r, first=r == 1)
        else:
            _hb_traces(go, fig, frf, key, quantity if key != "spl_db" else "spl_db", element, r, linear=True,
                       first=r == 1)
        fig.update_yaxes(title_text=panel_title if rows == 1 else _label(quantity if key != "spl_db" else key),
                         row=r, col=1)
    rpm = _engine(frf)
    if frf.check is None:
        _regions(fig, frf, rpm or 1.0, rows)
    height = 120 + _PANEL_HEIGHT * rows
    _layout(fig, height, rpm, rows)
    return fig


def frequency_response_html(frf: Any, *, quantity: str = "rms", summary: str | None = None,
                            title: str | None = None) -> str:
    """A self-contained interactive HTML page of a frequency response (module docstring).

    Parameters
    ----------
    frf : FrequencyResponse
        Any law: a smooth one (one panel per clearance element of a chain), or one with jumps or
        friction (``frf.check``: its exact shooting rows, every branch).
    quantity : str, default "rms"
        The column drawn: ``mean``, ``rms``, ``rms_ac``, ``p2p``, ``acc_p2p``, ``delta_min``,
        ``delta_max`` (``spl_db`` for a result with sound paths); a law with jumps or friction:
        ``mean``, ``rms``, ``rms_ac``, ``p2p``, ``acc_p2p`` (a chain: ``rms`` or ``mean``).
    summary : str, optional
        The text below the plot (default ``frf.summary()``).
    title : str, optional
        The page's and the figure's title.

    Returns
    -------
    str
        The HTML document (about 5 MB: plotly.js is inside it).

    Raises
    ------
    ImportError
        Without plotly (:data:`PLOTLY_MISSING`).
    """
    fig = _frf_figure(frf, quantity=quantity, title=title)
    return _page(fig, title or _frf_title(frf), frf.summary() if summary is None else summary)


# --------------------------------------------------------------------------------------------
# Comparison
# --------------------------------------------------------------------------------------------
_DIRECTIONS = {"up": ("triangle-up", "#1f77b4", "sweep up (Ω increasing)"),
               "down": ("triangle-down", "#ff7f0e", "sweep down (Ω decreasing)")}


def _sweep_traces(go: Any, fig: Any, sweep: Any, y: np.ndarray, rpm: float | None, row: int, *, first: bool,
                  stick: np.ndarray | None = None) -> None:
    """The up (▲) and down (▼) sweep points, with their period, settled or not, in the hover."""
    scale = rpm or 1.0
    direction = np.asarray(sweep.direction).astype(str)
    omega = np.asarray(sweep.omega, dtype=float)
    period = np.asarray(sweep.period, dtype=int)
    settled = np.asarray(sweep.settled, dtype=bool)
    for d, (symbol, colour, name) in _DIRECTIONS.items():
        sel = np.flatnonzero(direction == d)
        if sel.size == 0:
            continue
        text = [f"{name}<br>{_where(omega[i], rpm)}<br>rms = {_num(y[i], ' rad')}<br>"
                + ("failed" if period[i] < 0 else "no period ≤ 8 (non-periodic)" if period[i] == 0 else f"period {period[i]}")
                + ("" if settled[i] else ", not settled")
                + ("" if stick is None or not math.isfinite(stick[i]) else f"<br>held {stick[i]:.3g} of the period")
                for i in sel]
        fig.add_trace(go.Scatter(x=(omega[sel] * scale).tolist(), y=[None if not math.isfinite(v) else v for v in y[sel]],
                                 hovertext=text, hovertemplate="%{hovertext}<extra></extra>", mode="markers", name=name,
                                 legendgroup=name, showlegend=first,
                                 marker={"symbol": symbol, "color": colour, "size": 7,
                                         "line": {"width": 0.5, "color": "black"}}), row=row, col=1)


def _compare_figure(comparison: Any, *, title: str | None = None, samples: int = 128) -> Any:
    """The plotly Figure of ``comparison``: see :func:`compare_html`."""
    _require_plotly()
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    from ._compare import _steady_history
    from ._orbit import window_periods

    frf, sweep = comparison.frf, comparison.sweep
    rpm = _engine(frf)
    scale = rpm or 1.0
    if frf.check is not None:
        names = tuple(getattr(frf.check, "element_names", ()) or ())
    else:
        names = tuple(getattr(frf, "element_names", ()) or ())
    m = max(1, len(names))
    at = tuple(comparison.at)
    n = len(at)
    cols = max(1, n)
    specs = [[{"colspan": cols}] + [None] * (cols - 1) for _ in range(m)]
    titles = [f"element {nm}" if len(names) > 1 else "" for nm in names] or [""]
    letters = string.ascii_lowercase
    if n:
        specs.append([{} for _ in range(n)])
        titles += [f"({letters[j % 26]}) {_where(w, rpm)}: {why}" for j, (w, why) in enumerate(zip(at, comparison.reasons))]
    fig = make_subplots(rows=len(specs), cols=cols, specs=specs, subplot_titles=titles, vertical_spacing=0.09,
                        horizontal_spacing=0.05, row_heights=[1.6] * m + ([1.0] if n else []))
    for k in range(m):
        if frf.check is not None:
            _check_traces(go, fig, frf, "rms", k, k + 1, first=k == 0)
            y = np.asarray(sweep.element_columns[f"{names[k]}_rms"] if names else sweep.rms, dtype=float)
            key = f"{names[k]}_stick_fraction" if names else "stick_fraction"
            held = sweep.extra_columns.get(key)
            _sweep_traces(go, fig, sweep, y, rpm, k + 1, first=k == 0,
                          stick=None if held is None else np.asarray(held, dtype=float))
        else:
            key = f"{names[k]}_rms" if names else "rms"
            _hb_traces(go, fig, frf, key, "rms", k, k + 1, linear=False, first=k == 0)
            y = np.asarray(sweep.element_columns[key] if names else sweep.rms, dtype=float)
            _sweep_traces(go, fig, sweep, y, rpm, k + 1, first=k == 0)
        fig.update_yaxes(title_text=f"{names[k]}: δ rms (rad)" if names else "δ rms (rad)", row=k + 1, col=1)
        for j, w in enumerate(at):
            fig.add_vline(x=w * scale, line={"color": "#595959", "width": 1, "dash": "dashdot"}, row=k + 1, col=1,
                          label={"text": f"({letters[j % 26]})", "textposition": "end", "textangle": 0, "font": {"size": 12},
                                 "yanchor": "top"})
        fig.update_xaxes(title_text=_x_title(rpm), row=k + 1, col=1)
    if frf.check is None:
        _regions(fig, frf, scale, m)
    hist = m + 1
    for j, (w, orbit, sims) in enumerate(zip(at, comparison.orbits, comparison.simulations)):
        n_win = window_periods([s.period for s in orbit.solutions] + [s.period for s in sims.values()])
        for i, sol in enumerate(orbit.solutions):
            h = orbit.time_history(i, samples=samples, periods=n_win)
            word = "stable" if sol.stable else "unstable"
            fig.add_trace(go.Scatter(
                x=np.asarray(h["t"]).tolist(), y=np.asarray(h["delta"]).tolist(), mode="lines",
                name=f"HB P{sol.period} {word} (rms {sol.rms:.3g})", showlegend=False,
                hovertemplate=f"HB period {sol.period}, {word}, rms {sol.rms:.4g}<br>t = %{{x:.4g}} s<br>δ = %{{y:.4g}} rad"
                              "<extra></extra>",
                line={"color": _COLOURS[i % len(_COLOURS)], "dash": "solid" if sol.stable else "dash",
                      "width": 1.8 if sol.stable else 1.2}), row=hist, col=j + 1)
        for d, state in sims.items():
            symbol, colour, name = _DIRECTIONS.get(d, ("circle", "black", d))
            t, x = _steady_history(state, w, n_win, samples)
            step = max(1, samples // 24)
            per = f"period {state.period}" if state.period else "no period ≤ 8"
            fig.add_trace(go.Scatter(
                x=t[::step].tolist(), y=x[::step].tolist(), mode="markers", name=f"{d} sweep", showlegend=False,
                hovertemplate=f"{name}: {per}, rms {state.rms:.4g}<br>t = %{{x:.4g}} s<br>δ = %{{y:.4g}} rad<extra></extra>",
                marker={"symbol": symbol, "color": colour, "size": 6, "line": {"width": 0.4, "color": "black"}}),
                row=hist, col=j + 1)
        fig.update_xaxes(title_text="time t (s)", row=hist, col=j + 1)
        if j == 0:
            fig.update_yaxes(title_text="δ (rad)", row=hist, col=1)
    height = 120 + 380 * m + (_HISTORY_HEIGHT if n else 0)
    heading = title or ("Frequency response against the time-domain sweep"
                        + (f" (H = {frf.harmonics_text()})" if frf.check is None else " (exact orbits)"))
    fig.update_layout(height=height, hovermode="closest", template="plotly_white", legend={"font": {"size": 11}},
                      margin={"l": 70, "r": 20, "t": 50, "b": 55})
    fig.layout.meta = {"title": heading}  # the page's heading
    return fig


def compare_html(comparison: Any, *, summary: str | None = None, title: str | None = None, samples: int = 128) -> str:
    """A self-contained interactive HTML page of a comparison (module docstring): the frequency
    response (per element of a chain; a law with jumps or friction: its exact rows) with the up
    and down sweep points, the examined frequencies marked, and δ(t) there (``samples`` per
    forcing period) of every HB orbit and of the sweeps' steady states.

    ``summary``: the text below the plot (default ``comparison.summary()``). Raises ImportError
    without plotly."""
    fig = _compare_figure(comparison, title=title, samples=samples)
    return _page(fig, fig.layout.meta["title"], comparison.summary() if summary is None else summary)


# --------------------------------------------------------------------------------------------
# Response map
# --------------------------------------------------------------------------------------------
def _map_figure(response_map: Any, *, quantity: str = "rms", title: str | None = None) -> Any:
    """The plotly Figure of ``response_map``: see :func:`map_html`."""
    _require_plotly()
    import plotly.graph_objects as go

    from ._map import MAP_QUANTITIES, NO_SOLUTION_COLOR, RATTLE_COLOR, _edges, _outline, _panels, _values

    if quantity not in MAP_QUANTITIES:
        raise ValueError(f"`quantity` must be one of {', '.join(map(repr, MAP_QUANTITIES))}, got {quantity!r}")
    if quantity == "spl" and not getattr(response_map, "has_sound", False):
        raise ValueError("`quantity` \"spl\" needs a map computed with sound paths; this one has none")
    field, bar_label, empty_label = MAP_QUANTITIES[quantity]
    params = list(response_map.parameters)
    if not params:
        raise ValueError("`response_map` varies no parameter; there is nothing to draw")
    name = params[0].name
    key = params[0].key
    ylabel = (name if name == key else f"{name} ({key})") + (" (deg)" if params[0].degrees else "")
    by_name = {q.name: q for q in params}
    omega = np.asarray(response_map.omega, dtype=float)
    N = omega.size
    rpm = getattr(response_map, "speed_rpm", None)
    x = omega if rpm is None else np.asarray(rpm, dtype=float)
    yv = np.asarray([params[0].shown(v) for v in params[0].values], dtype=float)  # degrees where the case gave them
    xe, ye = _edges(x), _edges(yv)
    xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
    every = [_values(c, field, N) for c in response_map.cells]
    finite = np.concatenate(every)[np.isfinite(np.concatenate(every))] if every else np.zeros(0)
    zmin, zmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    unit = " dB" if quantity == "spl" else " rad"
    panels = _panels(response_map, name)
    traces_per_panel = 3
    for p, (panel_title, cells) in enumerate(panels):
        z = np.array([_values(response_map.cells[k], field, N) for k in cells])
        rattle = np.array([np.asarray(response_map.cells[k].rattle, dtype=bool) for k in cells])
        text = []
        for k in cells:
            c = response_map.cells[k]
            v = _values(c, field, N)
            row = []
            for j in range(N):
                row.append(
                    f"{_where(omega[j], None if rpm is None else (x[j] / omega[j]))}<br>"
                    + ", ".join(f"{nm} = {by_name[nm].shown(val):.5g}" + (" deg" if by_name[nm].degrees else "")
                                if nm in by_name else f"{nm} = {val:.5g}" for nm, val in c.values.items()) + "<br>"
                    + (f"{field} = {_num(v[j], unit)}" if math.isfinite(v[j]) else empty_label)
                    + f"<br>stable period-1: {int(c.n_stable[j])} of {int(c.n_solutions[j])}"
                    + f"<br>stable periods: {c.periods_stable[j] or 'none'}"
                    + (f"<br>regime {c.regime_max_stable[j]}" if c.regime_max_stable[j] else "")
                    + f"<br>{'<b>impacts (rattle)</b>' if c.rattle[j] else 'rattle-free'}"
                    + ("" if c.status == "ok" else f"<br>combination {c.status}"))
            text.append(row)
        visible = p == 0
        fig_traces = [
            go.Heatmap(x=xe.tolist(), y=ye.tolist(), z=z.tolist(), text=text, hovertemplate="%{text}<extra></extra>",
                       colorscale="Viridis", zmin=zmin, zmax=zmax, colorbar={"title": {"text": bar_label, "side": "right"}},
                       name=panel_title or "map", visible=visible, showscale=True),
        ]
        ri, rj = np.nonzero(rattle)
        fig_traces.append(go.Scatter(x=xc[rj].tolist(), y=yc[ri].tolist(), mode="markers", name="impacts (rattle)",
                                     hoverinfo="skip", visible=visible, legendgroup="impacts",
                                     marker={"symbol": "x-thin", "size": 6, "line": {"width": 1, "color": RATTLE_COLOR},
                                             "color": RATTLE_COLOR}))
        xs: list[Any] = []
        ys: list[Any] = []
        for (x0, y0), (x1, y1) in _outline(~rattle, xe, ye):
            xs += [float(x0), float(x1), None]
            ys += [float(y0), float(y1), None]
        fig_traces.append(go.Scatter(x=xs, y=ys, mode="lines", name="rattle-free boundary", hoverinfo="skip",
                                     visible=visible, legendgroup="outline", line={"color": "black", "width": 2}))
        if p == 0:
            fig = go.Figure(fig_traces)
        else:
            fig.add_traces(fig_traces)
    grey = f"rgb({', '.join(str(int(round(255 * float(NO_SOLUTION_COLOR))))  for _ in range(3))})"
    fig.add_trace(go.Scatter(x=[None], y=[None], mode="markers", name=empty_label, hoverinfo="skip",
                             marker={"symbol": "square", "size": 12, "color": grey}))
    if len(panels) > 1:
        total = len(fig.data)
        buttons = []
        for p, (panel_title, _) in enumerate(panels):
            vis = [False] * total
            vis[p * traces_per_panel:(p + 1) * traces_per_panel] = [True] * traces_per_panel
            vis[-1] = True
            buttons.append({"label": panel_title, "method": "update", "args": [{"visible": vis}]})
        fig.update_layout(updatemenus=[{"buttons": buttons, "direction": "down", "x": 0.0, "xanchor": "left",
                                        "y": 1.0, "yanchor": "bottom", "pad": {"b": 8}, "showactive": True}])
    heading = title or ("Response map: " + ("largest stable rms" if quantity == "rms" else
                                            "largest stable sound pressure level")
                        + ", impacts ×, rattle-free outlined")
    height = 560
    fig.update_layout(height=height, template="plotly_white", plot_bgcolor=grey, meta={"title": heading},
                      hovermode="closest", legend={"orientation": "h", "y": -0.18, "x": 0.0},
                      margin={"l": 70, "r": 20, "t": 60 if len(panels) > 1 else 20, "b": 90})
    fig.update_xaxes(title_text=_x_title(None if rpm is None else 1.0), range=[float(min(xe[0], xe[-1])),
                                                                              float(max(xe[0], xe[-1]))],
                     showgrid=False, zeroline=False)
    fig.update_yaxes(title_text=ylabel, range=[float(min(ye[0], ye[-1])), float(max(ye[0], ye[-1]))],
                     showgrid=False, zeroline=False)
    return fig


def map_html(response_map: Any, *, quantity: str = "rms", summary: str | None = None, title: str | None = None) -> str:
    """A self-contained interactive HTML page of a response map (module docstring): the heat map
    over Ω (rpm with an engine) and the first varied parameter, one panel per combination of the
    others chosen from a menu; each cell's hover names its Ω, the parameters, the largest stable
    rms (``quantity="spl"``: sound pressure level), the stable counts and periods, the regime and
    whether it impacts.

    ``summary``: the text below the plot (none by default). Raises ImportError without plotly."""
    fig = _map_figure(response_map, quantity=quantity, title=title)
    return _page(fig, fig.layout.meta["title"], summary)
