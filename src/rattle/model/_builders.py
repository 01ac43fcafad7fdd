"""Sub-system builders: drivetrain parts described as a data sheet gives them → ordinary chain pieces.

Each builder states its physics and returns the objects every analysis already solves
(:class:`~rattle.model.Element`, :class:`~rattle.model.Chain`): nothing here is new numerics.

* :func:`clutch_damper` — a multi-stage flywheel–clutch damper, drive (δ > 0) and coast (δ < 0)
  sides asymmetric, optional free play around zero → an element with a
  :class:`~rattle.model.Piecewise` law.
* :func:`hub_spline` — a clutch hub spline with free play → an element with a
  :class:`~rattle.model.Backlash` law.
* :func:`gear_pair` — two gears meshing along the line of action (base radii, mesh stiffness,
  mesh damping ratio, backlash) → the equivalent free torsional two-inertia chain on gear 1's
  side (:class:`GearPair`, which also maps results back to gear 2).
* :func:`loose_gear` — a loose (idler) gear with a drag torque rattling against a gear whose
  motion the engine imposes → a one-inertia base-excited chain in the relative coordinate
  (:class:`LooseGear`).

Angles are in rad, stiffnesses in N m/rad (N/m for a mesh), lengths in m: the configuration
reader (:mod:`._table_shapes`) converts degrees, millimetres and micrometres before calling these.
A mesh backlash above a tenth of the smaller base radius is warned about
(:func:`backlash_warning`: a length in mm written as m).
Every refusal is a ``ValueError``/``TypeError`` naming the argument in backticks.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._chain import Chain, Element, Link, Torque
from ._elastic import Backlash, Piecewise, _check_real, _check_real_sequence

__all__ = ["GearPair", "LooseGear", "MAX_BACKLASH_RATIO", "backlash_warning", "clutch_damper", "gear_pair", "hub_spline",
           "loose_gear"]


#: The smallest non-zero free play of a damper (rad): 1e-12 rad (6e-11 degrees) is no free play.
MIN_FREE_PLAY = 1e-12


def _positive(name: str, value: object) -> float:
    x = _check_real(name, value)
    if not x > 0:
        raise ValueError(f"`{name}` must be > 0, got {x!r}")
    return x


def _stage_side(side: str, stiffness: object, angles: object, half_play: float) -> tuple[tuple[float, ...],
                                                                                            tuple[float, ...]]:
    """The checked stage stiffnesses and end angles of one side of a damper."""
    k = _check_real_sequence(f"{side}_stiffness", stiffness)
    a = _check_real_sequence(f"{side}_angles", angles)
    if not k:
        raise ValueError(f"`{side}_stiffness` must hold at least one stage stiffness (N m/rad), got []")
    for i, v in enumerate(k):
        if not v > 0:
            raise ValueError(f"`{side}_stiffness[{i}]` must be > 0 N m/rad (a stage stiffness), got {v!r}; "
                             "free play is given by `free_play`, not by a stage of zero stiffness")
    if len(a) != len(k) - 1:
        raise ValueError(
            f"`{side}_angles` must have one entry fewer than `{side}_stiffness` ({len(k)} stages need "
            f"{len(k) - 1} end angles: where each stage ends and the next begins; the last stage continues, "
            f"give a stop as a last, stiff stage), got {len(a)}"
        )
    for i, v in enumerate(a):
        if not v > 0:
            raise ValueError(f"`{side}_angles[{i}]` must be > 0 (angles are measured from δ = 0 outwards, on "
                             f"the coast side too), got {v!r}")
        if i and not v > a[i - 1]:
            raise ValueError(f"`{side}_angles` must be strictly increasing, got {list(a)!r} "
                             f"({side}_angles[{i}] = {v!r} is not > {side}_angles[{i - 1}] = {a[i - 1]!r})")
    if a and not a[0] > half_play:
        raise ValueError(f"`{side}_angles[0]` must be > free_play/2 = {half_play!r} (the first stage begins at the "
                         f"end of the free play), got {a[0]!r}")
    return k, a


def _damper_law(*, drive_stiffness: Sequence[float], drive_angles: Sequence[float], coast_stiffness: Sequence[float],
               coast_angles: Sequence[float], free_play: float = 0.0) -> tuple[float, Piecewise]:
    """The stiffness K_e and the law f of a multi-stage damper (:func:`clutch_damper`)."""
    p = _check_real("free_play", free_play)
    if p < 0:
        raise ValueError(f"`free_play` must be >= 0 (the total free play around zero), got {p!r}")
    if 0 < p < MIN_FREE_PLAY:
        raise ValueError(f"`free_play` must be 0 (none) or at least {MIN_FREE_PLAY:g} rad, got {p!r}: a free play "
                         "that small is no free play (its two stage ends would be closer than the crossings of a "
                         "motion can be told apart); give 0")
    kd, ad = _stage_side("drive", drive_stiffness, drive_angles, p / 2)
    kc, ac = _stage_side("coast", coast_stiffness, coast_angles, p / 2)
    K = max(*kd, *kc)
    # from the coast stop inwards, then outwards on the drive side
    breakpoints = [-x for x in reversed(ac)]
    slopes = [x / K for x in reversed(kc)]
    if p > 0:
        breakpoints += [-p / 2, p / 2]
        slopes += [0.0]
    elif kc[0] != kd[0]:  # the slope changes at δ = 0 (equal first stages: one stage across zero)
        breakpoints += [0.0]
    else:
        slopes.pop()
    breakpoints += list(ad)
    slopes += [x / K for x in kd]
    return K, Piecewise(breakpoints=tuple(breakpoints), slopes=tuple(slopes))


def clutch_damper(*, drive_stiffness: Sequence[float], drive_angles: Sequence[float],
                  coast_stiffness: Sequence[float], coast_angles: Sequence[float], free_play: float = 0.0,
                  name: str = "damper", between: tuple[int, int] = (1, 2)) -> Element:
    """A multi-stage flywheel–clutch damper from its data sheet, as a chain element.

    Drive side (δ = θ_i − θ_j > 0, engine ahead): stages of stiffness k_1 … k_n (N m/rad,
    ``drive_stiffness``) ending at the twist angles a_1 < … < a_{n−1} (rad, ``drive_angles``,
    measured from δ = 0; the last stage continues — a stop is a last, stiff stage). Coast side
    (δ < 0): ``coast_stiffness`` c_1 … c_m and ``coast_angles`` g_1 < … < g_{m−1} given as positive
    angles, measured from 0 towards negative δ. ``free_play`` p ≥ 0: the total free play, centred
    on 0 (the first stages begin at ±p/2). With a_0 = g_0 = p/2 and a_n = g_m = ∞, the damper
    torque is

        T(δ) =  Σ_{j=1..n} k_j · max(0, min(δ, a_j) − a_{j−1})        δ ≥ 0,
        T(δ) = −Σ_{j=1..m} c_j · max(0, min(−δ, g_j) − g_{j−1})       δ < 0,

    continuous, piecewise linear, T(0) = 0. It is returned as the element's stiffness
    K_e = max(k, c) (the stiffest stage has slope 1) and a Piecewise law f = T/K_e with
    breakpoints −g_{m−1} … −g_1, −p/2, p/2, a_1 … a_{n−1} and slopes c_m … c_1, 0, k_1 … k_n
    (over K_e). Without free play the breakpoint is 0, or none when c_1 = k_1. Preload and
    hysteresis (friction) are not modelled here.

    Parameters
    ----------
    drive_stiffness, coast_stiffness : sequence of float
        Stage stiffnesses (N m/rad), each > 0, from zero outwards.
    drive_angles, coast_angles : sequence of float
        End angles (rad, > 0, strictly increasing, the first > p/2), one fewer than the stages.
    free_play : float, default 0
        Total free play (rad) around zero.
    name, between :
        The element's name and inertias (i, j) (δ = θ_i − θ_j).

    Returns
    -------
    Element
    """
    K, law = _damper_law(drive_stiffness=drive_stiffness, drive_angles=drive_angles,
                        coast_stiffness=coast_stiffness, coast_angles=coast_angles, free_play=free_play)
    return Element(name=name, between=between, stiffness=K, law=law)


def hub_spline(*, backlash: float, stiffness: float, name: str = "spline",
               between: tuple[int, int] = (1, 2)) -> Element:
    """A clutch hub spline as a chain element: total free play ``backlash`` (rad), centred, and the
    torsional ``stiffness`` (N m/rad) when the teeth are engaged:

        T(δ) = K (δ − b) for δ > b,  0 for |δ| ≤ b,  K (δ + b) for δ < −b,   b = backlash / 2,

    i.e. an element of stiffness K with the :class:`~rattle.model.Backlash` law of half-gap b.
    """
    total = _positive("backlash", backlash)
    k = _positive("stiffness", stiffness)
    return Element(name=name, between=between, stiffness=k, law=Backlash(b=total / 2.0))


#: A gear mesh's backlash (total play along the line of action) above this fraction of the smaller
#: base radius is implausible, and warned about (:func:`backlash_warning`): real meshes have
#: 0.01 … 0.5 mm on base radii of 10 … 200 mm (b_los / r ≈ 1e-4 … 0.02), and at r/10 the half-gap is
#: already ≥ 1/20 rad (2.9°) of either gear; a unit slip (mm written as m: × 1000) lands far above.
MAX_BACKLASH_RATIO = 0.1

#: The length units a backlash may be written in, largest first (a value in one, mistaken for the
#: next, is 1000 times too large): name, factor to m, the key suffix of a case file.
_LENGTHS = (("m", 1.0, ""), ("mm", 1e-3, "_mm"), ("µm", 1e-6, "_um"))


def backlash_warning(backlash: float, base_radii: Sequence[float], *, key: str = "backlash", unit: str = "m",
                     in_file: bool = False) -> str | None:
    """The warning for a gear mesh's total play ``backlash`` (m) above :data:`MAX_BACKLASH_RATIO`
    times the smaller base radius — b_los > 0.1 · min(r1, r2), implausible for a gear mesh — naming
    ``key`` as written in ``unit`` (``"m"``, ``"mm"`` or ``"µm"``) and the likely unit: the next
    smaller one (mm for m, µm for mm), with the key or value that says it (``in_file``: the case
    file's ``KEY_mm``/``KEY_um``; else the value in m to pass). None when plausible."""
    r = min(float(v) for v in base_radii)
    if not backlash > MAX_BACKLASH_RATIO * r:
        return None
    names = [u[0] for u in _LENGTHS]
    i = names.index(unit)
    written = backlash / _LENGTHS[i][1]
    in_m = "" if unit == "m" else f" ({backlash:.4g} m)"
    text = (f"`{key}` = {written:g} {unit}{in_m} of play along the line of action is more than {MAX_BACKLASH_RATIO:g} × "
            f"the smaller base radius ({r:g} m): implausible for a gear mesh, whose backlash is some 0.01 … 0.5 mm")
    if i + 1 == len(_LENGTHS):
        return text + "; check the value"
    likely, factor, suffix = _LENGTHS[i + 1]
    base = key[: -len(_LENGTHS[i][2])] if _LENGTHS[i][2] else key
    fix = (f"write `{base}{suffix}` = {written:g} instead" if in_file
           else f"pass {key} = {written * factor:g} (m) instead")
    return f"{text}; if {written:g} was meant in {likely}, {fix}"


def _mesh(base_radii: object, mesh_stiffness: object, mesh_damping_ratio: object,
          backlash: object) -> tuple[float, float, float, float, float]:
    if isinstance(base_radii, (str, bytes)) or not hasattr(base_radii, "__len__") or len(base_radii) != 2:  # type: ignore[arg-type]
        raise TypeError(f"`base_radii` must be a pair [r1, r2] of base-circle radii (m), got {base_radii!r}")
    r1 = _positive("base_radii[0]", base_radii[0])  # type: ignore[index]
    r2 = _positive("base_radii[1]", base_radii[1])  # type: ignore[index]
    km = _positive("mesh_stiffness", mesh_stiffness)
    zeta = _check_real("mesh_damping_ratio", mesh_damping_ratio)
    if not zeta > 0:
        raise ValueError(f"`mesh_damping_ratio` must be > 0 (typical gear meshes: 0.03 … 0.1), got {zeta!r}")
    b_los = _positive("backlash", backlash)
    return r1, r2, km, zeta, b_los


def _mesh_law(half_gap: float, backlash: float, base_radii: tuple[float, float]) -> Backlash:
    """The mesh's backlash law of half-gap ``half_gap`` (rad), with one warning when the play
    ``backlash`` (m) is implausible for the gear geometry (:func:`backlash_warning`): the half-gap
    is then not warned about again as an angle (:class:`~rattle.model.Backlash` warns beyond π/2
    rad, which b_los > π r implies)."""
    message = backlash_warning(backlash, base_radii)
    if message is None:
        return Backlash(b=half_gap)
    warnings.warn(message, UserWarning, stacklevel=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Backlash(b=half_gap)


@dataclass(frozen=True, slots=True)
class GearPair:
    """A gear pair reduced to gear 1's side (:func:`gear_pair`).

    ``chain``: inertias (J1, J2') with J2' = J2 (r1/r2)², the mesh element ``name`` (stiffness
    K = k_m r1², Backlash of half-gap b = b_los/(2 r1)) and the mesh damping link c. Results of the
    chain are on gear 1's side: inertia 2's angle, velocity and acceleration are θ2' = (r2/r1) θ2,
    so gear 2's are ``ratio`` × them (:meth:`to_gear2`), its torques T2 = T2' / ``ratio``; the mesh
    element's δ = θ1 − θ2' is the mesh deflection along the line of action s = r1 δ (m,
    :meth:`line_of_action`).
    """

    chain: Chain
    #: r1 / r2: gear 2's angle = ratio × the chain's θ2' (and T2' = ratio × T2).
    ratio: float
    base_radii: tuple[float, float]
    #: J2' = J2 (r1/r2)², kg m².
    reflected_inertia: float
    #: K = k_m r1², N m/rad.
    stiffness: float
    #: c = 2 ζ_m sqrt(K J_eq), N m s/rad.
    damping: float
    #: b = b_los / (2 r1), the half-gap in rad of gear 1.
    half_gap: float

    def to_gear2(self, reflected: Any) -> Any:
        """Gear 2's angle (velocity, acceleration) from the chain's inertia 2: θ2 = (r1/r2) θ2'."""
        return np.asarray(reflected, dtype=float) * self.ratio

    def line_of_action(self, delta: Any) -> Any:
        """The mesh deflection along the line of action s = r1 θ1 − r2 θ2 = r1 δ (m)."""
        return np.asarray(delta, dtype=float) * self.base_radii[0]


def gear_pair(*, base_radii: Sequence[float], inertias: Sequence[float], mesh_stiffness: float,
              mesh_damping_ratio: float, backlash: float, torques: Sequence[Torque] = (),
              links: Sequence[Link] = (), name: str = "mesh", speed_order: float | None = None) -> GearPair:
    """Two meshing gears → the equivalent torsional two-inertia chain on gear 1's side.

    Gear k has base radius r_k (m) and inertia J_k (kg m²); θ2 counts positive in the sense in
    which gear 1 drives gear 2. The teeth meet along the line of action, where the mesh
    deflection is s = r1 θ1 − r2 θ2 and the mesh force is F = k_m g(s) + c_m s' (k_m mesh
    stiffness, N/m; g the backlash law of half-gap b_los/2, b_los = ``backlash``, the total play
    along the line of action, m; c_m mesh damping, N s/m):

        J1 θ1'' + r1 F = T1,        J2 θ2'' − r2 F = T2.

    With θ2' = (r2/r1) θ2 the deflection is s = r1 (θ1 − θ2') = r1 δ and g(r1 δ) = r1 f(δ) with f
    the backlash law of half-gap b = b_los/(2 r1); multiplying gear 2's equation by r1/r2:

        J1 θ1''  + K f(δ) + c δ' = T1,
        J2' θ2'' − K f(δ) − c δ' = T2',       δ = θ1 − θ2',

    J2' = J2 (r1/r2)², K = k_m r1² (N m/rad), c = c_m r1², T2' = T2 r1/r2: an ordinary free chain
    of two inertias with the mesh element (K, Backlash(b)) and a damping link c. The mesh damping
    ratio ζ_m is that of the linear mesh mode, m_eq s'' + c_m s' + k_m s with
    m_eq = 1/(r1²/J1 + r2²/J2) = J_eq/r1², J_eq = J1 J2'/(J1 + J2'): c = 2 ζ_m sqrt(K J_eq).
    The linear mesh frequency is ω_m² = k_m (r1²/J1 + r2²/J2) = K/J_eq.

    ``torques`` act on gear 1 (``inertia = 1``, N m) and gear 2 (``inertia = 2``, N m on gear 2's
    shaft: multiplied by r1/r2 here); ``links`` to ground (``between = [1, 0]`` or ``[2, 0]``,
    gear 2's in N m/rad and N m s/rad of gear 2: multiplied by (r1/r2)²) make the pair grounded.

    Returns
    -------
    GearPair
        The chain and what maps its results back to gear 2 (``ratio`` = r1/r2).
    """
    r1, r2, km, zeta, b_los = _mesh(base_radii, mesh_stiffness, mesh_damping_ratio, backlash)
    J = _check_real_sequence("inertias", inertias)
    if len(J) != 2:
        raise ValueError(f"`inertias` must be the two gear inertias [J1, J2] (kg m^2), got {len(J)} values")
    J1 = _positive("inertias[0]", J[0])
    J2 = _positive("inertias[1]", J[1])
    ratio = r1 / r2
    J2r = J2 * ratio**2
    K = km * r1**2
    Jeq = J1 * J2r / (J1 + J2r)
    c = 2.0 * zeta * math.sqrt(K * Jeq)
    b = b_los / (2.0 * r1)
    out_links = [Link(between=(1, 2), damping=c)]
    for k, link in enumerate(links):
        if not isinstance(link, Link):
            raise TypeError(f"`links[{k}]` must be a Link, got {link!r}")
        if link.between not in ((1, 0), (2, 0)):
            raise ValueError(f"`links[{k}].between` must be [1, 0] or [2, 0] (a gear to ground: the mesh joins the "
                             f"gears), got {list(link.between)}")
        scale = 1.0 if link.between[0] == 1 else ratio**2
        out_links.append(Link(between=link.between, stiffness=link.stiffness * scale, damping=link.damping * scale))
    out_torques = []
    for k, tq in enumerate(torques):
        if not isinstance(tq, Torque):
            raise TypeError(f"`torques[{k}]` must be a Torque, got {tq!r}")
        if tq.inertia not in (1, 2):
            raise ValueError(f"`torques[{k}].inertia` must be 1 (gear 1) or 2 (gear 2), got {tq.inertia}")
        s = 1.0 if tq.inertia == 1 else ratio
        out_torques.append(Torque(inertia=tq.inertia, mean=tq.mean * s, amplitudes=tuple(a * s for a in tq.amplitudes),
                                  phases=tq.phases))
    chain = Chain(inertias=(J1, J2r), links=tuple(out_links),
                  elements=(Element(name=name, between=(1, 2), stiffness=K, law=_mesh_law(b, b_los, (r1, r2))),),
                  torques=tuple(out_torques), speed_order=speed_order)
    return GearPair(chain=chain, ratio=ratio, base_radii=(r1, r2), reflected_inertia=J2r, stiffness=K, damping=c,
                    half_gap=b)


@dataclass(frozen=True, slots=True)
class LooseGear:
    """A loose gear rattling against an imposed driving gear (:func:`loose_gear`).

    ``chain``: one inertia J2 joined to ground by the mesh element ``name`` (K = k_m r2²,
    Backlash of half-gap b = b_los/(2 r2)) and the damping link c; its coordinate is the relative
    angle δ = (r1/r2) θ1 − θ2 (rad of gear 2): the mesh deflection along the line of action is
    s = r2 δ (:meth:`line_of_action`), and the loose gear's absolute angular acceleration is
    θ2'' = (r1/r2) θ1'' − δ''.
    """

    chain: Chain
    #: r1 / r2.
    ratio: float
    base_radii: tuple[float, float]
    #: K = k_m r2², N m/rad.
    stiffness: float
    #: c = 2 ζ_m sqrt(K J2), N m s/rad.
    damping: float
    #: b = b_los / (2 r2), the half-gap in rad of gear 2.
    half_gap: float

    def line_of_action(self, delta: Any) -> Any:
        """The mesh deflection along the line of action s = r1 θ1 − r2 θ2 = r2 δ (m)."""
        return np.asarray(delta, dtype=float) * self.base_radii[1]


def loose_gear(*, base_radii: Sequence[float], inertia: float, mesh_stiffness: float, mesh_damping_ratio: float,
               backlash: float, drive_acceleration: Sequence[float], drive_phases: Sequence[float] | None = None,
               drag_torque: float = 0.0, name: str = "mesh", speed_order: float | None = None) -> LooseGear:
    """A loose (idler) gear of inertia J2 (``inertia``) rattling against a driving gear 1 whose
    motion is imposed: gear 1 turns with the shaft the engine drives, its angular acceleration
    θ1''(t) = Σ_n A_n cos(nΩt + φ_n) (``drive_acceleration`` A_n in rad/s², harmonics n = 1, 2, …
    of Ω; ``drive_phases`` φ_n). The loose gear carries a constant drag torque T_d ≥ 0
    (``drag_torque``, N m, churning and bearing losses) that holds it back against gear 1.

    With s = r1 θ1 − r2 θ2 and F = k_m g(s) + c_m s' as in :func:`gear_pair`, gear 2 obeys
    J2 θ2'' = r2 F − T_d. In the relative coordinate δ = (r1/r2) θ1 − θ2 = s/r2 (rad of gear 2,
    g(r2 δ) = r2 f(δ), f the backlash law of half-gap b = b_los/(2 r2)):

        J2 δ'' + c δ' + K f(δ) = J2 (r1/r2) θ1''(t) + T_d,     K = k_m r2²,  c = c_m r2²,

    with c = 2 ζ_m sqrt(K J2) (the mesh mode of a gear against an imposed motion: m_eq = J2/r2²).
    This is the standard base-excited formulation, written as a grounded one-inertia chain
    (mesh element and damping link to ground, torque T_d + J2 (r1/r2) Σ A_n cos(nΩt + φ_n) on it)
    that the existing numerics solve exactly. It is used rather than giving gear 1 a very large
    inertia driven by a torque: that would only approximate the imposed motion and spread the
    system's time scales over the inertia ratio, while the relative coordinate is exact.
    δ > 0: contact on the drive flank (the drag keeps the mean there).

    Returns
    -------
    LooseGear
    """
    r1, r2, km, zeta, b_los = _mesh(base_radii, mesh_stiffness, mesh_damping_ratio, backlash)
    J2 = _positive("inertia", inertia)
    acc = _check_real_sequence("drive_acceleration", drive_acceleration)
    if not acc:
        raise ValueError("`drive_acceleration` must hold at least one harmonic amplitude (rad/s^2), got []")
    if drive_phases is not None:
        phases = _check_real_sequence("drive_phases", drive_phases)
        if len(phases) != len(acc):
            raise ValueError(f"`drive_phases` must have one entry per `drive_acceleration` amplitude ({len(acc)}), "
                             f"got {len(phases)}")
    else:
        phases = (0.0,) * len(acc)
    td = _check_real("drag_torque", drag_torque)
    if td < 0:
        raise ValueError(f"`drag_torque` must be >= 0 N m (its magnitude; it opposes the loose gear's rotation), "
                         f"got {td!r}")
    ratio = r1 / r2
    K = km * r2**2
    c = 2.0 * zeta * math.sqrt(K * J2)
    b = b_los / (2.0 * r2)
    chain = Chain(inertias=(J2,), links=(Link(between=(1, 0), damping=c),),
                  elements=(Element(name=name, between=(1, 0), stiffness=K, law=_mesh_law(b, b_los, (r1, r2))),),
                  torques=(Torque(inertia=1, mean=td, amplitudes=tuple(J2 * ratio * a for a in acc),
                                  phases=phases),),
                  speed_order=speed_order)
    return LooseGear(chain=chain, ratio=ratio, base_radii=(r1, r2), stiffness=K, damping=c, half_gap=b)
