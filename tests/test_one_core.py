"""One exact flow (issue 23, item 2), counted from the source with ``ast``:

- one Newton loop on the period map (:meth:`rattle.timeint.ShootingProblem.solve`): no other
  function of the package both runs a period map and halves a step;
- one trajectory type: every exact integrator's trajectory is an
  :class:`~rattle.timeint.ExactTrajectory`, declares none of its shared fields again and answers
  ``states(t)`` and ``measures()`` (the settling loop reads nothing else);
- one ``make_integrator``: no other function picks an integrator class by the kind of system;
- at most two public classes named ``*Integrator`` (the flow and its scalar kernel);
- one continuation (item 3): the ε-ladder and the held elements' ladder run on
  :class:`~rattle.continuation.ContinuationStepper` (no loop of ``analysis._regularisation`` or
  ``analysis._held_limit`` calls a Newton solve itself: :data:`HAND_ROLLED_LADDERS` is empty).
- one problem type (item 1): the numerics dispatch on three model types — the user-facing
  ``Model`` and ``Chain`` and the reduced :class:`~rattle.model.System`, which carries its
  elements' whole laws (jumps, friction; the single equation is n = m = 1) — and on no class of a
  discontinuous law; the exact flow picks its path by a predicate on the system's properties.
"""

from __future__ import annotations

import ast
import dataclasses
import pickle
from pathlib import Path

import pytest

import rattle.timeint as timeint

SRC = Path(__file__).resolve().parents[1] / "src" / "rattle"
MODULES = sorted(SRC.rglob("*.py"))
INTEGRATORS = ("ExactIntegrator", "SystemIntegrator", "NonsmoothIntegrator", "FrictionIntegrator")

#: Functions outside this helper's reach that still pick an integrator by the kind of system
#: (``rattle.results`` may change only its import lines in this step): they should call
#: :func:`rattle.timeint.make_integrator`.
LADDERS_LEFT: set[tuple[str, str]] = set()

#: Modules whose loops still call a Newton solve themselves (a hand-rolled continuation): none.
#: The held elements' ladder was the last (its rungs needed a damped Newton: the stepper's
#: corrector now damps when ``NewtonOptions.damped``, with the natural predictor).
HAND_ROLLED_LADDERS: set[str] = set()

#: What solves R = 0 directly: a Newton at a fixed parameter, a step of it, the corrector.
NEWTON_CALLS = {"solve_fixed", "newton_step", "correct", "_solve", "solve_harmonic_balance"}


def _name(path: Path) -> str:
    parts = ("rattle", *path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


TREES = {_name(path): ast.parse(path.read_text(encoding="utf-8")) for path in MODULES}


def _functions() -> list[tuple[str, ast.FunctionDef]]:
    return [(mod, node) for mod, tree in TREES.items() for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)]


def _calls(node: ast.AST) -> set[str]:
    """Names of the functions and methods called inside ``node``."""
    names = set()
    for n in ast.walk(node):
        if isinstance(n, ast.Call):
            f = n.func
            names.add(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))
    return names


def _runs_the_period_map(node: ast.AST) -> bool:
    """Calls an integrator's period map (``advance``, ``propagate``), a ShootingProblem's
    (``period_map``, ``newton_step`` on ``problem``) or the loop's own evaluation."""
    for n in ast.walk(node):
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute):
            if n.func.attr in {"advance", "propagate", "period_map", "_evaluate"}:
                return True
            receiver = n.func.value
            name = receiver.attr if isinstance(receiver, ast.Attribute) else getattr(receiver, "id", "")
            if n.func.attr == "newton_step" and name == "problem":
                return True
    return False


def _halves(node: ast.AST) -> bool:
    """``x *= 0.5`` or ``x = 0.5 * x`` inside a loop of ``node``."""
    for loop in (n for n in ast.walk(node) if isinstance(n, (ast.For, ast.While))):
        for n in ast.walk(loop):
            if isinstance(n, ast.AugAssign) and isinstance(n.op, ast.Mult) and \
                    isinstance(n.value, ast.Constant) and n.value.value == 0.5:
                return True
    return False


def test_one_newton_loop_on_the_period_map() -> None:
    """Only ShootingProblem.solve runs the period map (advance, propagate, period_map,
    newton_step) inside a step-halving loop."""
    loops = [(mod, f.name) for mod, f in _functions() if _halves(f) and _runs_the_period_map(f)]
    assert loops == [("rattle.timeint._shooting_problem", "solve")], loops


def test_the_shooters_and_the_settling_loop_call_the_one_loop() -> None:
    shooters = {f.name: f for mod, f in _functions() if mod == "rattle.timeint._shooting"}
    for name in ("shoot_periodic_orbit", "shoot_system_orbit", "shoot_nonsmooth_orbit", "shoot_friction_orbit"):
        assert "_solve" in _calls(shooters[name]), name
    assert "solve" in _calls(shooters["_solve"])
    flows = [node for node in ast.walk(TREES["rattle.analysis._steady"]) if isinstance(node, ast.ClassDef)
             and node.name == "_Flow"]
    assert len(flows) == 1 and "solve" in _calls(next(f for f in flows[0].body if getattr(f, "name", "") == "shoot"))
    others = {(mod, f.name): f for mod, f in _functions()
              if (mod, f.name) in {("rattle.analysis._exact_branch", "damped_newton"),
                                   ("rattle.analysis._tori", "simulate_torus")}}
    assert len(others) == 2
    for key, f in others.items():
        assert "solve" in _calls(f), key


def test_one_trajectory_type() -> None:
    """Every exact trajectory is an ExactTrajectory; its shared fields are declared once."""
    shared = {f.name for f in dataclasses.fields(timeint.ExactTrajectory)}
    assert {"omega", "t0", "t1", "state0", "state1", "sensitivity", "t_start", "t_end"} <= shared
    for cls in (timeint.Trajectory, timeint.SystemTrajectory, timeint.NonsmoothTrajectory, timeint.FrictionTrajectory):
        assert issubclass(cls, timeint.ExactTrajectory), cls
        assert not shared & set(cls.__dict__.get("__annotations__", {})), (cls, shared & set(cls.__annotations__))
        assert "segment_index" not in cls.__dict__, cls
        assert "states" in cls.__dict__ and "measures" in cls.__dict__, cls


def test_one_make_integrator() -> None:
    """No function but rattle.timeint.make_integrator constructs integrators of two kinds (an
    if-ladder on the kind of system); the ones left are listed in LADDERS_LEFT."""
    ladders = {(mod, f.name) for mod, f in _functions() if len(_calls(f) & set(INTEGRATORS)) >= 2}
    assert ladders - LADDERS_LEFT == set(), ladders - LADDERS_LEFT


def _public_integrator_classes() -> list[str]:
    found = []
    for path in MODULES:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and node.name.endswith("Integrator") and not node.name.startswith("_"):
                found.append(node.name)
    return sorted(found)


def test_at_most_two_public_integrator_classes() -> None:
    assert len(_public_integrator_classes()) <= 2, _public_integrator_classes()


def test_one_flow_takes_every_system() -> None:
    """ExactIntegrator(system) is the flow of every kind of system (its paths are private
    subclasses), built for that system; the folded names are gone from the public lists."""
    import rattle
    from rattle.model import Friction, System

    model = rattle.reference_case()
    chain = model.system()
    systems = (model, chain, System.from_model(model, friction=Friction(levels=0.01)),
               chain.with_friction((0.01,)))
    for system in systems:
        integ = timeint.ExactIntegrator(system)
        assert isinstance(integ, timeint.ExactIntegrator) and type(integ) is not timeint.ExactIntegrator
        assert timeint.built_for(integ, system) and integ.system is system
        assert type(pickle.loads(pickle.dumps(integ))) is type(integ)  # the paths go to worker processes
    for name in (*INTEGRATORS[1:], "NonsmoothOptions"):
        assert name not in timeint.__all__ and name not in rattle.__all__, name
        with pytest.warns(DeprecationWarning, match="ExactIntegrator|FlowOptions"):
            assert getattr(timeint, name) in (timeint.ExactIntegrator, timeint.FlowOptions)
    with pytest.raises(TypeError, match="`system`"):
        timeint.ExactIntegrator("clutch")


#: The model types the numerics may dispatch on (``isinstance``): what a law needs is a property.
MODEL_TYPES = {"Model", "Chain", "System"}
#: The model types folded into System (issue 23 item 1).
FOLDED_TYPES = {"NonsmoothSystem", "FrictionSystem"}


def _isinstance_types(tree: ast.AST) -> list[str]:
    """The names given as the class (or in the tuple of classes) of every ``isinstance`` call."""
    names = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == "isinstance" and len(n.args) == 2:
            kinds = n.args[1].elts if isinstance(n.args[1], ast.Tuple) else [n.args[1]]
            names += [k.id if isinstance(k, ast.Name) else k.attr for k in kinds if isinstance(k, (ast.Name, ast.Attribute))]
    return names


def test_one_problem_type() -> None:
    """No isinstance dispatch on a folded model type, no class of them defined; every model type
    dispatched on is Model, Chain or System (the old tree had 40 isinstance calls naming NonsmoothSystem
    and FrictionSystem, five model types)."""
    used = {name for tree in TREES.values() for name in _isinstance_types(tree)}
    folded = [(mod, name) for mod, tree in TREES.items() for name in _isinstance_types(tree) if name in FOLDED_TYPES]
    assert folded == [], folded
    defined = {n.name for tree in TREES.values() for n in ast.walk(tree) if isinstance(n, ast.ClassDef)}
    assert not defined & FOLDED_TYPES
    model_types = {n for n in used if n.endswith("System") or n in {"Model", "Chain"}} - {"RegularisedSystemBalance"}
    assert model_types == MODEL_TYPES, model_types
    # the exact flow's paths are chosen by predicates on the system, not by its class
    from rattle.timeint._exact_flow import ExactIntegrator

    assert ExactIntegrator._PATHS and all(not isinstance(takes, type) for takes, _ in ExactIntegrator._PATHS)


def test_what_a_law_needs_is_a_property_of_the_system() -> None:
    """The single equation and a chain with friction are Systems; the path follows the properties."""
    import rattle
    from rattle.model import Friction, System

    model = rattle.reference_case()
    single = System.from_model(model, friction=Friction(levels=0.01))
    chain = model.system().with_friction((0.01,))
    assert single.is_single_equation and single.discontinuous and single.has_friction and not single.has_jumps
    assert (single.n, single.m, single.c, single.k) == (1, 1, model.c, model.k)
    assert not chain.is_single_equation and chain.discontinuous and chain.continuous().laws is None
    assert chain.continuous() is chain.continuous() and not chain.continuous().discontinuous
    assert not model.system().discontinuous
    with pytest.raises(ValueError, match="single equation"):
        chain.c  # noqa: B018
    assert pickle.loads(pickle.dumps(single)) == single  # the single equation compares by value


def _loops_calling_newton(tree: ast.AST) -> list[int]:
    """Line numbers of the ``for``/``while`` loops of ``tree`` that call a Newton solve
    (:data:`NEWTON_CALLS`) themselves."""
    return [loop.lineno for loop in ast.walk(tree) if isinstance(loop, (ast.For, ast.While))
            and _calls(loop) & NEWTON_CALLS]


def test_the_ladders_run_on_the_stepper() -> None:
    """No loop of the regularisation ladder or of the held elements' ladder calls a Newton solve
    (the old ladders did: Newton at each rung, the step in log ε or log s halved by hand); each
    builds a ContinuationStepper on a WidthHomotopy."""
    for mod, name in (("rattle.analysis._regularisation", "regularisation_limit"),
                      ("rattle.analysis._held_limit", "held_limit")):
        tree = TREES[mod]
        assert _loops_calling_newton(tree) == [], mod
        ladder = next(f for f in ast.walk(tree) if isinstance(f, ast.FunctionDef) and f.name == name)
        assert {"ContinuationStepper", "WidthHomotopy"} <= _calls(ladder), mod
    ladders = ("rattle.analysis._regularisation", "rattle.analysis._held_limit")
    assert {mod for mod in ladders if _loops_calling_newton(TREES[mod])} == HAND_ROLLED_LADDERS
