"""``--quantity`` of ``rattle frf``, ``sweep``, ``compare`` and ``map``: what the figure draws and
what the summary's "largest" line reports, checked against what the case can give."""

from __future__ import annotations

from typing import Any

import click

from ..errors import ConfigError

#: The quantities ``--quantity`` takes, with their units.
QUANTITIES: dict[str, str] = {"rms": "rad", "rms_ac": "rad", "p2p": "rad", "acc_p2p": "rad/s²", "spl_db": "dB"}

#: What a response map records (``rattle map --quantity``): the quantity → ``plot_map``'s.
MAP_QUANTITY = {"rms": "rms", "rms_ac": "rms_ac", "spl_db": "spl"}

quantity_option = click.option(
    "--quantity", type=click.Choice(list(QUANTITIES)), default="rms", show_default=True,
    help="What the figure draws and the summary's 'largest' line reports: rms of δ (with the mean "
         "twist), rms_ac (about the mean: the rattle), p2p (peak to peak of δ), acc_p2p (of δ''), or "
         "spl_db (the sound pressure level; needs [[paths]]). Refused where the case cannot give it.")


def check_quantity(quantity: str, run_config: Any, command: str) -> None:
    """Exit 2 (ConfigError naming ``--quantity`` and the rule) on a quantity ``command`` cannot
    give for this case: spl_db without ``[[paths]]`` or on a law with jumps or friction (no
    Fourier coefficients to carry through the paths); on such a law anything but rms for frf and
    compare (their figure is the exact check's rms and stick fraction); p2p and acc_p2p for map
    (a map records the largest stable rms, its rms_ac and the sound pressure level)."""
    if quantity == "rms":
        return
    discontinuous = bool(getattr(run_config, "discontinuous", False))
    if quantity == "spl_db" and not run_config.paths:
        raise ConfigError("`--quantity spl_db` needs sound paths: the configuration has no [[paths]] (the sound "
                          "pressure level is the motion carried through them); add them or choose another quantity")
    if quantity == "spl_db" and discontinuous:
        raise ConfigError("`--quantity spl_db` is not available for a law with jumps or friction: the sound paths need "
                          "the harmonic-balance Fourier coefficients of a continuous law")
    if discontinuous and command in ("frf", "compare"):
        raise ConfigError(f"`--quantity {quantity}`: `rattle {command}` on a law with jumps or friction draws the exact "
                          "check's rms and stick fraction; only --quantity rms is available there (rattle sweep "
                          "takes rms_ac, p2p and acc_p2p)")
    if command == "map" and quantity not in MAP_QUANTITY:
        raise ConfigError(f"`--quantity {quantity}`: a response map records the largest stable rms, its rms_ac and "
                          "(with [[paths]]) the sound pressure level; choose rms, rms_ac or spl_db")


def _values(result: Any, quantity: str) -> Any:
    import numpy as np

    extra = getattr(result, "extra_columns", {}) or {}
    if quantity in extra:
        return np.asarray(extra[quantity], dtype=float)
    return np.asarray(getattr(result, quantity), dtype=float)


def largest_line(result: Any, quantity: str, where: str = "") -> str:
    """``largest stable QUANTITY v UNIT at Ω = w rad/s (n rpm) (regime)`` of a frequency response
    (its stable rows), or of a sweep (its settled rows: period ≥ 1); empty when none has a value."""
    import numpy as np

    y = _values(result, quantity)
    if hasattr(result, "stable") and hasattr(result, "branch"):
        rows = np.asarray(result.stable, dtype=bool)
        what = "largest stable"
    else:
        rows = np.asarray(result.period, dtype=int) >= 1
        what = "largest settled"
    rows = rows & np.isfinite(y)
    if not np.any(rows):
        return ""
    i = int(np.flatnonzero(rows)[np.argmax(y[rows])])
    w = float(result.omega[i])
    order = getattr(getattr(result, "model", None), "speed_order", None)
    rpm = "" if order is None else f" ({w * 60.0 / (2.0 * np.pi * order):.5g} rpm)"
    regime = getattr(result, "regime", None)
    tail = f" ({regime[i]})" if regime is not None and str(regime[i]) else ""
    return f"{where}{what} {quantity} {y[i]:.5g} {QUANTITIES[quantity]} at Ω = {w:.5g} rad/s{rpm}{tail}"


def with_largest(summary: str, quantity: str, *results: Any, where: tuple[str, ...] = ()) -> str:
    """``summary`` with the 'largest' line of ``quantity`` of each result appended (none for rms:
    the summary has it already)."""
    if quantity == "rms":
        return summary
    lines = [largest_line(r, quantity, w) for r, w in zip(results, where or ("",) * len(results))]
    return "\n".join([summary, *(line for line in lines if line)])


def map_largest_line(response_map: Any, quantity: str) -> str:
    """``\nlargest stable QUANTITY over the map: v UNIT at NAME = x, …, Ω = w rad/s`` for rms_ac and
    spl_db (empty for rms: the map's summary reports its rattle-free intervals by rms already)."""
    import numpy as np

    field = {"rms_ac": "rms_ac_max_stable", "spl_db": "spl_max_stable_db"}.get(quantity)
    if field is None:
        return ""
    best: tuple[float, Any, int] | None = None
    for (_index, values), cell in zip(response_map.combinations(), response_map.cells):
        v = getattr(cell, field, None)
        if v is None:
            continue
        v = np.asarray(v, dtype=float)
        if np.any(np.isfinite(v)):
            j = int(np.nanargmax(v))
            if best is None or v[j] > best[0]:
                best = (float(v[j]), values, j)
    if best is None:
        return ""
    value, values, j = best
    w = float(response_map.omega[j])
    rpm = getattr(response_map, "speed_rpm", None)
    where = ", ".join(f"{k} = {x:g}" for k, x in values.items())
    speed = f"Ω = {w:.5g} rad/s" + ("" if rpm is None else f" ({float(rpm[j]):.5g} rpm)")
    return f"\nlargest stable {quantity} over the map: {value:.5g} {QUANTITIES[quantity]} at {where}, {speed}"


__all__ = ["map_largest_line", "QUANTITIES", "MAP_QUANTITY", "quantity_option", "check_quantity", "largest_line", "with_largest"]
