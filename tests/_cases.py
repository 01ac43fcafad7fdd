"""Configuration texts shared by the tests (one source for the reference clutch as TOML)."""

from __future__ import annotations


def clutch_toml(omega: tuple[float, float] = (0.1, 3.0), harmonics: int = 32) -> str:
    """The paper's reference clutch as a configuration file, over ``omega`` with ``harmonics``."""
    return f"""\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
omega = [{omega[0]!r}, {omega[1]!r}]
harmonics = {harmonics}
"""
