"""Checks of the command line's options at the boundary, all before any computation: the
output folder, the numbers (``--points``, ``--workers``, ``--omega``, ``--period``, ``--at``)
and the file's analysis settings with the options that override them.

Each refusal is a :class:`rattle.ConfigError` naming the option in backticks, the value, the
rule and the fix (exit status 2). The checks that need neither numpy nor the model run first
(:func:`precheck`), so that a refusal answers at once; the bounds are the library's own
(:mod:`rattle._limits`), so the command line and the Python front ends refuse the same values.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..errors import ConfigError

if TYPE_CHECKING:  # annotations only: the numpy-based layers are imported when a command runs
    from ..io import AnalysisSettings
    from ..model import Model

__all__ = [
    "MAX_PERIOD", "DIRECTIONS", "VIRTUAL_FILESYSTEMS", "output_path", "override_analysis", "check_output_dir",
    "precheck", "as_bad_input", "check_points", "check_workers", "check_omega", "check_period", "parse_at",
    "MAX_OMEGA_POINTS", "check_omega_points", "check_scheduler", "speed_options", "check_rpm", "orbit_speed",
    "orbit_omega", "check_hb_options",
]

#: Most grid frequencies ``rattle map --omega-points`` accepts (each is an exact solve of every
#: branch per combination).
MAX_OMEGA_POINTS = 10_000

#: Largest period (multiple of the forcing period) that ``rattle orbit --period`` accepts.
MAX_PERIOD = 8
#: The values of ``rattle sweep --direction``.
DIRECTIONS = ("up", "down", "both")

#: Longest file name a command writes plus its staging folder and temporary suffix (bytes): the
#: room ``--output`` must leave below the file system's path limit.
_PATH_ROOM = 128


def output_path(_ctx: click.Context, _param: click.Parameter, value: str) -> Path:
    """``-o``: a non-blank path (``-o ""`` is refused: it would silently mean the current folder)."""
    if not value.strip():
        raise ConfigError(
            f"`--output` must name a folder, got {value!r}; give e.g. -o rattle-out (or -o . for the current folder)"
        )
    return Path(value)


def speed_options(
    model: Any, omega_min: float | None, omega_max: float | None, rpm_min: float | None, rpm_max: float | None
) -> tuple[float | None, float | None, dict[str, str]]:
    """``--rpm-min`` / ``--rpm-max`` (crankshaft rpm) as the forcing frequencies Ω (rad/s) of the
    model's engine (``speed_order`` q_0: Ω = q_0 · 2π/60 · rpm), with the option names for the
    messages (``{"omega_min": "--rpm-min"}``) to pass to :func:`override_analysis` as ``labels``.

    Refused (ConfigError): an rpm option without an engine in the model, both ``--omega-min`` and
    ``--rpm-min`` (or the max pair), an rpm that is not a finite number > 0.
    """
    labels: dict[str, str] = {}
    out = {"min": omega_min, "max": omega_max}
    if rpm_min is not None and rpm_max is not None and not rpm_min < rpm_max:
        raise ConfigError(f"`--rpm-min` must be < `--rpm-max`, got {rpm_min!r} and {rpm_max!r} rpm: the speed range is "
                          "empty; give the lower speed first and make the upper one larger")
    for which, rpm in (("min", rpm_min), ("max", rpm_max)):
        if rpm is None:
            continue
        option = f"--rpm-{which}"
        if out[which] is not None:
            raise ConfigError(f"`--omega-{which}` and `{option}` are both given: one end of the range in rad/s and "
                              "in rpm; give one of them")
        order = getattr(model, "speed_order", None)
        if order is None:
            raise ConfigError(f"`{option}` needs a model with an engine ([engine] in the configuration): without "
                              f"engine orders there is no crankshaft speed; give `--omega-{which}` in rad/s instead")
        if not (math.isfinite(rpm) and rpm > 0):
            raise ConfigError(f"`{option}` must be a finite crankshaft speed > 0 rpm, got {rpm!r}; use e.g. 800")
        out[which] = rpm * float(order) * 2.0 * math.pi / 60.0
        labels[f"omega_{which}"] = option
    return out["min"], out["max"], labels


def override_analysis(base: AnalysisSettings, model: Model | None = None, *, labels: dict[str, str] | None = None,
                      **options: Any) -> AnalysisSettings:
    """``base`` with the command-line options that were given (not None) replacing its fields.

    Parameters
    ----------
    base : AnalysisSettings
        Settings from the configuration file.
    model : Model, optional
        When given, the harmonic count is checked against its excitation harmonics.
    **options
        ``harmonics``, ``omega_min``, ``omega_max``; None means "not given".

    Returns
    -------
    AnalysisSettings

    Raises
    ------
    ConfigError
        If the combination breaks a rule; the message names the option (``--omega-min``) or the
        file key (``analysis.omega.2``) each value came from.
    """
    given = {name: value for name, value in options.items() if value is not None}
    names = {"omega_min": "analysis.omega.1", "omega_max": "analysis.omega.2", "harmonics": "analysis.harmonics"}
    names.update({name: "--" + name.replace("_", "-") for name in given})
    names.update({name: label for name, label in (labels or {}).items() if name in given})
    try:
        analysis = dataclasses.replace(base, **given)
    except (ValueError, TypeError) as exc:
        raise ConfigError(_config_io().rename_keys(str(exc), names)) from exc
    if model is not None:
        _config_io().check_harmonics(model, analysis.harmonics, names["harmonics"])
        if "omega_min" in given or "omega_max" in given:  # the file's own range was checked on loading
            from .. import _limits

            with as_bad_input():
                _limits.check_frequency_range(model, analysis.omega_min, analysis.omega_max,
                                              (names["omega_min"], names["omega_max"]))
    return analysis


#: File-system types that hold no files a user can keep (kernel interfaces, device nodes):
#: ``-o`` there is refused before computing (as root the permission check would pass).
VIRTUAL_FILESYSTEMS = frozenset({
    "proc", "sysfs", "devtmpfs", "devpts", "cgroup", "cgroup2", "debugfs", "tracefs", "securityfs", "pstore",
    "bpf", "configfs", "fusectl", "mqueue", "binfmt_misc", "autofs", "efivarfs", "selinuxfs", "hugetlbfs",
    "rpc_pipefs", "nsfs", "nfsd",
})
#: Path prefixes that are virtual on every Linux system (also when /proc/self/mountinfo is unreadable).
_VIRTUAL_ROOTS = ("/proc", "/sys", "/dev")
_REAL_UNDER_VIRTUAL = ("/dev/shm",)  # an ordinary tmpfs below /dev


def _mount_type(path: str) -> str | None:
    """The file-system type of the mount holding ``path`` (an absolute, resolved path), from
    /proc/self/mountinfo; None where that is unavailable."""
    try:
        with open("/proc/self/mountinfo", encoding="utf-8", errors="replace") as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    best, fstype = "", None
    for line in lines:
        left, _, right = line.partition(" - ")
        fields = left.split()
        if len(fields) < 5 or not right:
            continue
        mount = fields[4].replace("\\040", " ").replace("\\011", "\t").replace("\\134", "\\")
        inside = path == mount or path.startswith(mount.rstrip("/") + "/")
        if inside and len(mount) >= len(best):
            best, fstype = mount, right.split()[0]
    return fstype


def _limit(path: Path, name: str, default: int) -> int:
    try:
        value = os.pathconf(path, name)
    except (OSError, ValueError, AttributeError):
        return default
    return value if value and value > 0 else default


def check_output_dir(output: Path) -> None:
    """Refuse an output path that cannot become a writable directory, without creating anything.

    The rules, in order: not blank (checked when the option is read); no name component longer
    than the file system allows (``PC_NAME_MAX``, usually 255 bytes) and the whole path short
    enough to hold the staging folder and file names below ``PC_PATH_MAX``; no broken symbolic
    link on the way; an existing ``output`` is a directory; the nearest existing ancestor is a
    directory we may write in; not on a virtual file system (/proc, /sys, /dev, cgroup …).

    Raises
    ------
    ConfigError
        Naming ``--output``, the value and the rule broken.
    """
    shown = str(output)
    if len(shown) > 80:
        shown = shown[:60] + "…" + shown[-15:]
    absolute = Path(os.path.abspath(output))

    def as_given(p: Path) -> str:  # a path on the way, spelled as the user wrote --output
        if not output.is_absolute():
            with contextlib.suppress(ValueError):
                return str(p.relative_to(Path(os.path.abspath("."))))
        return str(p)

    # Walk down from the root: every name must fit the file system, the existing part must be
    # directories (no file, no broken link on the way), the rest is created by the run. os.path's
    # predicates are used because they answer False instead of raising on a too-long name.
    ancestor = Path(absolute.anchor or "/")
    existing = True
    name_max = _limit(ancestor, "PC_NAME_MAX", 255)
    for part in absolute.parts[1:]:
        size = len(os.fsencode(part))
        if size > name_max:
            part_shown = part if len(part) <= 40 else part[:30] + "…"
            raise ConfigError(
                f"`--output` has a folder name of {size} bytes ({part_shown!r}), more than the {name_max} "
                "this file system allows; use a shorter name"
            )
        if not existing:
            continue
        candidate = ancestor / part
        if os.path.isdir(candidate):
            ancestor = candidate
            name_max = _limit(ancestor, "PC_NAME_MAX", name_max)
        elif os.path.lexists(candidate):
            if os.path.islink(candidate) and not os.path.exists(candidate):
                raise ConfigError(
                    f"`--output` {shown!r}: {as_given(candidate)!r} is a broken symbolic link; remove it or choose "
                    "another path"
                )
            if candidate == absolute:
                raise ConfigError(
                    f"`--output` must be a directory, got {shown!r}, which is an existing file; choose another path"
                )
            raise ConfigError(
                f"`--output` {shown!r} cannot be created because {as_given(candidate)!r} is a file, "
                "not a directory; choose another path"
            )
        else:
            existing = False
    path_max = _limit(ancestor, "PC_PATH_MAX", 4096)
    size = len(os.fsencode(str(absolute)))
    if size + _PATH_ROOM > path_max:
        raise ConfigError(
            f"`--output` is a path of {size} bytes; with the file names below it, it must stay under the "
            f"{path_max} bytes this file system allows (at most {path_max - _PATH_ROOM}); use a shorter path"
        )
    resolved = os.path.realpath(ancestor)
    virtual_root = any(resolved == r or resolved.startswith(r + "/") for r in _VIRTUAL_ROOTS) and not any(
        resolved == r or resolved.startswith(r + "/") for r in _REAL_UNDER_VIRTUAL)
    fstype = _mount_type(resolved) if sys.platform.startswith("linux") else None
    if virtual_root or fstype in VIRTUAL_FILESYSTEMS:
        kind = f"a {fstype} file system" if fstype in VIRTUAL_FILESYSTEMS else "a virtual file system"
        raise ConfigError(
            f"`--output` {shown!r} lies on {kind} ({resolved}), which cannot hold output files; "
            "choose a folder on a disk"
        )
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError(
            f"`--output` {shown!r}: no permission to write in {str(ancestor)!r}; "
            "choose a writable directory"
        )


def precheck(config: Path | None, output: Path, *, harmonics: int | None = None, points: int | None = None,
             workers: int | None = None) -> None:
    """The checks that need neither numpy nor the model, first, so that a refusal answers at once:
    the configuration file is an existing regular file within the size limit (from ``stat``), the
    options' bounds (``rattle._limits``), the output folder."""
    if config is not None:
        from ..files import check_input_file  # no numpy

        check_input_file(config)
    if harmonics is not None:
        from .. import _limits

        with as_bad_input():
            _limits.check_harmonics(harmonics, "--harmonics")
    if points is not None:
        check_points(points)
    if workers is not None:
        check_workers(workers)
    check_output_dir(output)


@contextlib.contextmanager
def as_bad_input() -> Iterator[None]:
    """The library's argument checks (ValueError/TypeError naming the argument) as ConfigError."""
    try:
        yield
    except (ValueError, TypeError) as exc:
        if isinstance(exc, ConfigError):
            raise
        raise ConfigError(str(exc)) from exc


def check_points(points: int) -> int:
    """``--points`` N: an integer 2 … ``rattle._limits.MAX_SWEEP_POINTS`` (the library's rule)."""
    if points < 2:
        raise ConfigError(
            f"`--points` must be an integer >= 2 (frequencies per sweep direction), got {points}; use e.g. 200"
        )
    from .. import _limits

    with as_bad_input():
        return _limits.check_points(points, "--points")


def check_workers(workers: int) -> int:
    """``--workers``: an integer 1 … ``rattle._limits.MAX_WORKERS`` (2 runs the up and down sweeps at once)."""
    if workers < 1:
        raise ConfigError(f"`--workers` must be an integer >= 1, got {workers}; use 1 (serial) or 2")
    from .. import _limits

    with as_bad_input():
        return _limits.check_workers(workers, "--workers")


def check_omega_points(points: int) -> int:
    """``rattle map --omega-points`` N: an integer 2 … :data:`MAX_OMEGA_POINTS`."""
    if not 2 <= points <= MAX_OMEGA_POINTS:
        raise ConfigError(
            f"`--omega-points` must be an integer 2 … {MAX_OMEGA_POINTS} (frequencies of the map's grid), got "
            f"{points}; use e.g. 146"
        )
    return points


def check_scheduler(scheduler: str | None) -> str | None:
    """``rattle map --scheduler ADDRESS``: a non-blank address, and Dask distributed installed."""
    if scheduler is None:
        return None
    if not scheduler.strip():
        raise ConfigError(f"`--scheduler` must be a Dask scheduler address such as tcp://10.0.0.5:8786, got "
                          f"{scheduler!r}; leave it out to run on local processes")
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        raise ConfigError(f"`--scheduler` {scheduler!r} needs Dask distributed, which is not installed: "
                          "pip install 'rattle[dask]', or leave --scheduler out to run on local processes")
    # its form before any numerics load (the engine waits for the scheduler's handshake)
    from ..engines import check_scheduler_address

    return check_scheduler_address(scheduler, probe=False)


def check_rpm(rpm: float, option: str = "--rpm") -> float:
    """A crankshaft speed given on the command line: finite and > 0 rpm (its engine is checked
    once the file is read, :func:`orbit_omega`)."""
    if not (math.isfinite(rpm) and rpm > 0.0):
        raise ConfigError(f"`{option}` must be a finite crankshaft speed > 0 rpm, got {rpm!r}; use e.g. 800")
    return rpm


def orbit_speed(omega: float | None, rpm: float | None) -> None:
    """``rattle orbit``: exactly one of ``--omega`` (rad/s) and ``--rpm`` (crankshaft rpm), each
    finite and > 0 — checked before the file is read."""
    if omega is not None and rpm is not None:
        raise ConfigError(f"`--omega` and `--rpm` are both given ({omega!r} rad/s and {rpm!r} rpm): they name the "
                          "same forcing frequency; give one of them")
    if omega is None and rpm is None:
        raise ConfigError("`--omega` or `--rpm` is required: give the forcing frequency as --omega W (rad/s), or for a "
                          "configuration with [engine] the crankshaft speed as --rpm N")
    if omega is not None:
        check_omega(omega)
    else:
        check_rpm(rpm)  # type: ignore[arg-type]


def orbit_omega(model: Any, omega: float | None, rpm: float | None) -> tuple[float, str]:
    """The forcing frequency Ω (rad/s) of ``rattle orbit`` and the option that gave it: ``--omega``
    as given, or ``--rpm`` n as Ω = q_0 · 2π/60 · n with the model's engine order q_0 (refused
    without an engine: the case has no crankshaft speed)."""
    if rpm is None:
        return float(omega), "--omega"  # type: ignore[arg-type]
    order = getattr(model, "speed_order", None)
    if order is None:
        raise ConfigError(f"`--rpm` {rpm:g} needs a model with an engine ([engine] in the configuration): without "
                          "engine orders there is no crankshaft speed; give the forcing frequency as --omega in rad/s")
    return rpm * float(order) * 2.0 * math.pi / 60.0, "--rpm"


def check_omega(omega: float, option: str = "--omega", model: Model | None = None) -> float:
    """A forcing frequency given on the command line: finite and > 0 rad/s, and with ``model``
    within the library's bounds relative to its stiffest stage (``rattle._limits``)."""
    if not (math.isfinite(omega) and omega > 0.0):
        raise ConfigError(f"`{option}` must be a finite forcing frequency > 0 rad/s, got {omega!r}; use e.g. 0.8")
    if model is not None:
        from .. import _limits

        with as_bad_input():
            _limits.check_frequency(model, omega, option)
    return omega


def check_period(period: int, harmonics: int, forced: int) -> int:
    """``--period`` N: an integer 1 … 8 that the harmonic balance can hold with ``harmonics``."""
    if not 1 <= period <= MAX_PERIOD:
        raise ConfigError(
            f"`--period` must be an integer 1 … {MAX_PERIOD} (multiple of the forcing period), got {period}; "
            "use 1 for the primary response, n for a 1/n sub-harmonic"
        )
    if harmonics < forced * period:
        raise ConfigError(
            f"`--harmonics` must be >= {forced * period} to hold the excitation's harmonic {forced} at "
            f"`--period` {period}, got {harmonics}; raise `--harmonics`"
        )
    return period


def parse_at(text: str | None, omega_min: float | None = None, omega_max: float | None = None) -> list[float] | None:
    """``--at W1,W2,…``: comma-separated frequencies (rad/s), at most
    ``rattle._limits.MAX_DETAIL_FREQUENCIES`` of them; with ``omega_min``/``omega_max`` each
    within the analysis range. Without the range (before the configuration is read) the list's
    form and size are checked alone: no numpy is needed for that."""
    if text is None:
        return None
    from .._limits import MAX_DETAIL_FREQUENCIES  # the library's bound (numpy is not imported for it)

    parts = [p.strip() for p in text.split(",")]
    if not parts or any(not p for p in parts):
        raise ConfigError(f"`--at` must be a comma-separated list of frequencies such as 0.8,1.4, got {text!r}")
    if len(parts) > MAX_DETAIL_FREQUENCIES:
        shown = text if len(text) <= 60 else text[:40] + "…" + text[-12:]
        raise ConfigError(
            f"`--at` must hold at most {MAX_DETAIL_FREQUENCIES} frequencies, got {len(parts)} ({shown!r}): each one is "
            "a periodic-orbit search with simulations (seconds each); give fewer, or use `rattle sweep` for many "
            "frequencies"
        )
    values = []
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            raise ConfigError(f"`--at` must hold numbers (rad/s), got {part!r} in {text!r}") from None
        if not math.isfinite(value):
            raise ConfigError(f"`--at` frequencies must be finite, got {part!r}; choose frequencies inside the "
                              "analysis range")
        if omega_min is not None and omega_max is not None and not omega_min <= value <= omega_max:
            raise ConfigError(
                f"`--at` frequencies must be finite and within the analysis range {omega_min:g} … "
                f"{omega_max:g} rad/s, got {part!r}; choose frequencies inside the range or widen it"
            )
        values.append(value)
    return values


def _config_io() -> Any:
    """``rattle.io`` (numpy and the model), imported only where a check needs the configuration's rules."""
    from .. import io

    return io


def check_hb_options(run_config: Any, *, start: str, fixed_harmonics: bool) -> None:
    """Exit 2 (ConfigError naming the option) on ``rattle frf``'s options of the harmonic balance of
    a continuous law (``--start``, ``--fixed-harmonics``) given for a law with jumps or friction
    (one equation or a chain), which is solved by its ``[analysis] method`` instead."""
    if not (getattr(run_config, "discontinuous", False) or getattr(run_config, "chain_friction", False)):
        return
    for option, given in (("--start", start != "low"), ("--fixed-harmonics", fixed_harmonics)):
        if given:
            raise ConfigError(f"`{option}` must be left at the default for a law with jumps or friction: it sets the "
                              "harmonic balance of a continuous law; such a law is solved by [analysis] method = "
                              "\"shooting\" (exact shooting continuation, the default) or \"hb\" (the regularised "
                              "harmonic balance); leave it out")
