"""The user documentation stands alone and matches the code.

Every list checked here is derived from the code (the configuration loader's allowed keys, the
click commands and their options, the column lists, the status values), so that a key, option
or column added to the package without its documentation fails here.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import sys
import unicodedata
from pathlib import Path

import click
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
PAGES = ("index.md", "configuration.md", "cli.md", "outputs.md", "definitions.md", "python.md")

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def _text(name: str) -> str:
    return (DOCS / name).read_text(encoding="utf-8")


def _user_files() -> list[Path]:
    return [README, *sorted(DOCS.glob("**/*.md"))]


def _blocks(text: str, lang: str) -> list[str]:
    """The fenced code blocks of one info string (```lang ... ```)."""
    return re.findall(rf"^```{re.escape(lang)}[ \t]*\n(.*?)^```", text, flags=re.S | re.M)


def _mentions(text: str, word: str) -> bool:
    """``word`` occurs with no letter, digit, ``_`` or ``-`` on either side (``-o`` is not in ``--omega``)."""
    return re.search(rf"(?<![\w-]){re.escape(word)}(?![\w-])", text) is not None


# --------------------------------------------------------------------------------------------
# Standing alone
# --------------------------------------------------------------------------------------------
def test_every_page_exists_and_the_readme_lists_them():
    readme = README.read_text(encoding="utf-8")
    for name in PAGES:
        assert (DOCS / name).is_file(), f"docs/{name} is missing"
        assert f"docs/{name}" in readme, f"README.md does not list docs/{name}"
    index = _text("index.md")
    for name in PAGES[1:]:
        assert f"({name}" in index, f"docs/index.md does not link {name}"


# Each pattern points to material a user of the package does not have.
_FORBIDDEN = {
    "shared/": re.compile(r"shared/"),
    "../shared": re.compile(r"\.\./shared"),
    "shared folder": re.compile(r"shared\s+folder", re.I),
    "SPEC.md": re.compile(r"SPEC\.md"),
    "SPEC (the internal contract)": re.compile(r"\bSPEC\b"),
    "STYLE.md": re.compile(r"STYLE\.md"),
    "paper.txt": re.compile(r"paper\.txt"),
}


@pytest.mark.parametrize("path", _user_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_reference_to_a_folder_users_do_not_have(path):
    text = path.read_text(encoding="utf-8")
    for what, pattern in _FORBIDDEN.items():
        m = pattern.search(text)
        if m:
            line = text.count("\n", 0, m.start()) + 1
            pytest.fail(f"{path.relative_to(ROOT)}:{line} refers to {what!r}, which users do not have")


def _slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = heading.strip().lower()
    text = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return text.replace(" ", "-")


@pytest.mark.parametrize("path", _user_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_and_anchors_resolve(path):
    text = path.read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
            continue
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part) if file_part else path
        assert dest.exists(), f"{path.name}: link {target!r} points to a missing file"
        if anchor:
            headings = re.findall(r"^#+\s+(.*)$", dest.read_text(encoding="utf-8"), flags=re.M)
            assert anchor in {_slug(h) for h in headings}, f"{path.name}: anchor {target!r} has no heading"


def test_license_file_and_pyproject():
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License")
    assert "Copyright (c) 2026 rattle developers" in text
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert pyproject["project"]["license"] == "MIT"
    assert pyproject["project"]["license-files"] == ["LICENSE"]
    assert "LICENSE" in README.read_text(encoding="utf-8")


def test_readme_keeps_the_two_set_up_commands():
    readme = README.read_text(encoding="utf-8")
    assert "python3 -m pip install -e . && rattle demo" in readme
    assert 'python3 -m pip install -e ".[test]" && python3 -m pytest' in readme
    # ... inside a virtual environment, said in their explanation (not a third command)
    setup = readme.split("## Set-up", 1)[1].split("```", 1)[0]
    assert "python3 -m venv .venv && . .venv/bin/activate" in setup, setup


# --------------------------------------------------------------------------------------------
# Configuration keys
# --------------------------------------------------------------------------------------------
def _config_keys() -> list[str]:
    """Every key the loader accepts, dotted, from its allowed-key sets (the model tables' in
    rattle.model._tables, [analysis]'s in rattle.io._config) and the elastic laws."""
    from rattle.io import _config
    from rattle.model import ELASTIC_LAWS, _tables

    keys: list[str] = []
    for module in (_tables, _config):
        for name, value in vars(module).items():
            m = re.fullmatch(r"_([A-Z_]+)_KEYS", name)
            if not m or not isinstance(value, (tuple, list, set, frozenset, dict)):
                continue
            prefix = "" if m.group(1) == "TOP" else m.group(1).lower().replace("_", ".") + "."
            keys += [prefix + str(k) for k in value]
    assert "model" in keys and "excitation" in keys, f"no allowed-key sets found in rattle.model._tables: {keys}"
    assert "analysis.omega" in keys, f"no [analysis] keys found in rattle.io._config: {keys}"
    keys.append("model.elastic.type")
    for law in ELASTIC_LAWS.values():
        keys += [f"model.elastic.{p}" for p in _tables._law_params(law)]
    return sorted(set(keys))


@pytest.mark.parametrize("key", _config_keys())
def test_every_configuration_key_is_documented(key):
    assert f"`{key}`" in _text("configuration.md"), f"configuration key `{key}` is not in docs/configuration.md"


def test_elastic_types_and_defaults_are_documented():
    from rattle.io import DEFAULT_HARMONICS, DEFAULT_OMEGA
    from rattle.model import ELASTIC_LAWS

    text = _text("configuration.md")
    for name in ELASTIC_LAWS:
        assert f'`"{name}"`' in text, f"elastic type {name!r} is not in docs/configuration.md"
        assert f"`{name}`" in _text("definitions.md"), f"elastic type {name!r} is not in docs/definitions.md"
    assert f"`{DEFAULT_HARMONICS}`" in text
    assert f"`[{DEFAULT_OMEGA[0]}, {DEFAULT_OMEGA[1]}]`" in text


def test_configuration_examples_are_valid():
    """Every TOML block of the docs is accepted by the loader (fragments inside the full example)."""
    from rattle.io import config_from_dict

    blocks = [(name, b) for name in PAGES for b in _blocks(_text(name), "toml")]
    full = [tomllib.loads(b) for _, b in blocks if "excitation" in tomllib.loads(b)]
    assert full, "docs/configuration.md has no complete example"
    for name, block in blocks:
        data = tomllib.loads(block)
        if "excitation" not in data:  # a fragment: put it into the complete example
            data = {**full[0], "model": {**full[0]["model"], **data.get("model", {})}}
        config_from_dict(data, source_name=f"docs/{name}")


# --------------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------------
def _options(command: click.Command) -> set[str]:
    # The context the real command line builds: the group's settings (help_option_names
    # "-h", "--help") reach every sub-command (click caches a command's help option once it has
    # run, so a bare context would see "-h" or not depending on what ran before).
    from rattle.cli.main import cli

    parent = click.Context(cli, info_name="rattle", **cli.context_settings)
    ctx = click.Context(command, info_name=command.name, parent=None if command is cli else parent)
    if command is cli:
        ctx = parent
    out: set[str] = set()
    for param in command.get_params(ctx):
        if isinstance(param, click.Option):
            out |= set(param.opts) | set(param.secondary_opts)
    return out


def _sections(text: str) -> dict[str, str]:
    """``## `rattle NAME``` section bodies by command name."""
    parts = re.split(r"^## ", text, flags=re.M)
    out = {}
    for part in parts:
        m = re.match(r"`rattle (\w+)`", part)
        if m:
            out[m.group(1)] = part
    return out


def test_every_command_and_option_is_documented():
    from rattle.cli.main import cli

    text = _text("cli.md")
    sections = _sections(text)
    commands = dict(cli.commands)
    assert commands, "the rattle group has no commands"
    # Options every command has are documented once, under the general options.
    common = set.intersection(*(_options(c) for c in commands.values()))
    for opt in _options(cli) | common:
        assert _mentions(text, opt), f"option {opt} is not in docs/cli.md"
    for name, command in commands.items():
        assert name in sections, f"docs/cli.md has no section '## `rattle {name}`'"
        body = sections[name]
        for opt in _options(command) - common:
            assert _mentions(body, opt), f"option {opt} of `rattle {name}` is not in its section of docs/cli.md"
        for param in command.params:
            if isinstance(param.type, click.Choice):
                for choice in param.type.choices:
                    assert _mentions(body, str(choice)), f"`rattle {name}`: choice {choice!r} is not documented"
            if isinstance(param, click.Argument):
                assert param.human_readable_name in body


def _command_lines() -> list[tuple[str, list[str]]]:
    lines = []
    for page in _user_files():
        for block in _blocks(page.read_text(encoding="utf-8"), "bash"):
            for line in block.splitlines():
                line = line.split("#", 1)[0].strip()
                for part in line.split("&&"):
                    argv = shlex.split(part)
                    if argv and argv[0] == "rattle":
                        lines.append((page.name, argv))
    return lines


def test_command_examples_parse():
    """Every ``rattle …`` line in a bash block of the README and docs/ names a real command with
    real options and files, and click parses it as the command line would."""
    from rattle.cli.main import cli

    examples = _command_lines()
    assert len(examples) >= 10
    for page, argv in examples:
        args = argv[1:]
        while args and args[0].startswith("-"):  # group options: -v, --version
            assert args[0] in _options(cli), f"{page}: {' '.join(argv)}: unknown option {args[0]}"
            args = args[1:]
        if not args:
            continue
        name, rest = args[0], args[1:]
        assert name in cli.commands, f"{page}: {' '.join(argv)}: no command {name!r}"
        command = cli.commands[name]
        try:
            command.make_context(name, list(rest))
        except click.ClickException as exc:
            pytest.fail(f"{page}: {' '.join(argv)}: {exc.format_message()}")
        for token in rest:
            if token.startswith("examples/"):
                assert (ROOT / token).is_file(), f"{page}: {' '.join(argv)}: {token} does not exist"


# --------------------------------------------------------------------------------------------
# Outputs
# --------------------------------------------------------------------------------------------
def test_every_output_column_is_documented():
    from rattle.results import FRF_COLUMNS, NONSMOOTH_COLUMNS, NONSMOOTH_ORBIT_COLUMNS, ORBIT_COLUMNS, SWEEP_COLUMNS

    text = _text("outputs.md")
    for columns in (FRF_COLUMNS, SWEEP_COLUMNS, ORBIT_COLUMNS, NONSMOOTH_COLUMNS, NONSMOOTH_ORBIT_COLUMNS):
        assert f"`{','.join(columns)}`" in text, f"the header {','.join(columns)} is not in docs/outputs.md"
        for column in columns:
            assert f"`{column}`" in text, f"column `{column}` is not in docs/outputs.md"


def test_every_output_file_is_documented():
    import importlib

    sets = {name: value for module in ("rattle.cli.output", "rattle.demo")
            for name, value in vars(importlib.import_module(module)).items()
            if re.fullmatch(r"[A-Z]+_FILES", name) and isinstance(value, tuple)}
    assert {"FRF_FILES", "SWEEP_FILES", "ORBIT_FILES", "COMPARE_FILES", "DEMO_FILES"} <= set(sets), (
        f"output sets not found: {sorted(sets)}")
    outputs, cli_text = _text("outputs.md"), _text("cli.md")
    for name, files in sets.items():
        command = name.split("_")[0].lower()
        body = _sections(cli_text).get(command, "")
        for file in files:
            assert f"`{file}`" in outputs or file.startswith("fig"), f"{file} ({name}) is not in docs/outputs.md"
            assert f"`{file}`" in body, f"{file} is not in the `rattle {command}` section of docs/cli.md"


def test_labels_and_status_values_are_documented():
    from rattle.errors import Status
    from rattle.measures import REGIMES
    from rattle.stability import _classify

    outputs, definitions = _text("outputs.md"), _text("definitions.md")
    kinds = set(re.findall(r"``(\w+)``", _classify.classify_loss.__doc__ or ""))
    assert {"fold", "period_doubling"} <= kinds
    for word in (*REGIMES, *kinds):
        assert f"`{word}`" in outputs and f"`{word}`" in definitions, f"`{word}` is not documented"
    for status in Status:
        assert f"`{status.name.lower()}`" in outputs, f"status {status.name.lower()} is not in docs/outputs.md"


def test_region_kinds_are_documented():
    from rattle.analysis import _regimes

    kinds = {"superharmonic", "subharmonic", *getattr(_regimes, "UNSTABLE_KINDS", ())}
    kinds |= set(re.findall(r'Region\(\s*"(\w+)"', Path(_regimes.__file__).read_text(encoding="utf-8")))
    outputs = _text("outputs.md")
    for kind in sorted(kinds):
        assert f"| `{kind}` |" in outputs, f"region kind `{kind}` has no row in docs/outputs.md"


def test_option_fields_are_documented():
    import dataclasses

    import rattle

    text = _text("python.md")
    for cls in (rattle.HBOptions, rattle.NewtonOptions, rattle.ContinuationOptions, rattle.SteadyStateOptions):
        assert f"`{cls.__name__}`" in text
        for f in dataclasses.fields(cls):
            if f.init:
                assert f"`{f.name}`" in text, f"{cls.__name__}.{f.name} is not in docs/python.md"


def _documented_signatures() -> list[tuple[str, str, str]]:
    """``name(arguments)`` entries of the ```text blocks of the docs whose name is a public
    callable of rattle (``frequency_response``, ``rattle.analysis.nonsmooth_orbit``,
    ``Clutch``), as (page, name, arguments); continuation lines are joined."""
    import rattle

    out = []
    for path in sorted(DOCS.glob("*.md")):
        for block in _blocks(path.read_text(encoding="utf-8"), "text"):
            entries: list[str] = []
            for line in block.splitlines():
                if line.startswith(" ") and entries:
                    entries[-1] += " " + line.strip()
                else:
                    entries.append(line.strip())
            for entry in entries:
                for m in re.finditer(r"((?:rattle\.)?[A-Za-z_][\w.]*)\((.*?)\)(?=\s*->|\s{2,}|\s*$)", entry):
                    obj = rattle
                    for part in m.group(1).removeprefix("rattle.").split("."):
                        obj = getattr(obj, part, None)
                    if callable(obj):
                        out.append((path.name, m.group(1), m.group(2)))
    return out


def test_documented_signatures_match_the_code():
    """Every signature written out in the docs names the function's parameters in its order:
    all of them, or, where the entry ends in ``…``, some of them (the first may be renamed)."""
    import ast
    import inspect

    import rattle

    signatures = _documented_signatures()
    assert len(signatures) >= 15, signatures
    for page, name, arguments in signatures:
        partial = "…" in arguments
        args = ast.parse(f"def f({arguments.replace('…', '').rstrip(', ')}): pass").body[0].args
        documented = [a.arg for a in (*args.posonlyargs, *args.args, *args.kwonlyargs)]
        obj = rattle
        for part in name.removeprefix("rattle.").split("."):
            obj = getattr(obj, part)
        actual = [p for p in inspect.signature(obj).parameters if p != "self"]
        if partial:
            it = iter(actual[1:])
            assert all(a in it for a in documented[1:]), f"docs/{page}: {name}({arguments}) against {actual}"
        else:
            assert documented == actual, f"docs/{page}: {name} documents {documented}, the code has {actual}"


# --------------------------------------------------------------------------------------------
# Every code block runs on its own
# --------------------------------------------------------------------------------------------
#: The marker of an illustrative block, on the line before its fence; used only where a block
#: cannot run here (it needs a cluster, a licence, hours). docs/index.md states the convention.
NO_RUN = "<!-- no-run -->"


def _python_blocks() -> list[tuple[str, int, str]]:
    """Every ```python block of the README and docs/ as (page, line of the fence, code), the
    ones marked NO_RUN left out."""
    out = []
    for path in _user_files():
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"^```python[ \t]*\n(.*?)^```", text, flags=re.S | re.M):
            before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1].strip()
            if before == NO_RUN:
                continue
            out.append((str(path.relative_to(ROOT)), text.count("\n", 0, m.start()) + 1, m.group(1)))
    return out


_PY_BLOCKS = _python_blocks()


def test_the_no_run_marker_is_rare():
    """Illustrative blocks stay the exception: at most three, each an HTML comment line right
    before its fence."""
    marked = [path.name for path in _user_files()
              for _ in re.finditer(rf"^{re.escape(NO_RUN)}\n```", path.read_text(encoding="utf-8"), flags=re.M)]
    assert len(_PY_BLOCKS) >= 15 and len(marked) <= 3, (len(_PY_BLOCKS), marked)


def _private_names(code: str) -> list[str]:
    """Imports or attribute chains of ``rattle`` that go through a name starting with ``_``, or
    that name something a package does not list in its ``__all__``."""
    import ast
    import importlib.util

    def public(module: str, name: str) -> bool:
        if name.startswith("_"):
            return False
        try:
            mod = importlib.import_module(module)
        except ImportError:
            return False
        names = getattr(mod, "__all__", None)
        if names is None or name in names:
            return True
        return hasattr(mod, "__path__") and importlib.util.find_spec(f"{module}.{name}") is not None  # a sub-package

    bad = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "rattle":
            parts = node.module.split(".")
            bad += [node.module for i in range(1, len(parts)) if not public(".".join(parts[:i]), parts[i])]
            bad += [f"{node.module}.{a.name}" for a in node.names if not public(node.module, a.name)]
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if parts[0] == "rattle":
                    bad += [a.name for i in range(1, len(parts)) if not public(".".join(parts[:i]), parts[i])]
        elif isinstance(node, ast.Attribute):
            chain, inner = [node.attr], node.value
            while isinstance(inner, ast.Attribute):
                chain.insert(0, inner.attr)
                inner = inner.value
            if isinstance(inner, ast.Name) and inner.id == "rattle":
                module = "rattle"
                for name in chain:
                    if not public(module, name):
                        bad.append(f"{module}.{name}")
                        break
                    if importlib.util.find_spec(f"{module}.{name}") is None:
                        break
                    module = f"{module}.{name}"
    return sorted(set(bad))


@pytest.mark.parametrize("page,line,code", _PY_BLOCKS, ids=[f"{p}:{n}" for p, n, _ in _PY_BLOCKS])
def test_docs_use_public_names_only(page, line, code):
    assert not _private_names(code), f"{page}:{line} uses names that are not public: {_private_names(code)}"


def test_the_private_name_check_bites():
    assert _private_names("from rattle.maps._report import map_report") == ["rattle.maps._report"]
    assert _private_names("import rattle\nrattle.maps._report.map_report") == ["rattle.maps._report"]
    assert _private_names("from rattle.maps import map_report\nimport rattle\nrattle.io.read_csv") == []


@pytest.mark.parametrize("page,line,code", _PY_BLOCKS, ids=[f"{p}:{n}" for p, n, _ in _PY_BLOCKS])
def test_code_blocks_run_on_their_own(page, line, code, tmp_path, monkeypatch):
    """Each ```python block of the README and docs/ runs in a fresh namespace, in a folder that
    holds a copy of examples/ (the blocks name files as a user in the project folder does); the
    files it writes with ``to_csv``/``savefig`` exist afterwards, a frf.csv with the SPEC columns."""
    import shutil

    import matplotlib.pyplot as plt

    from rattle.io import read_csv
    from rattle.results import FRF_COLUMNS

    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "__docs__"}
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, f"{page}:{line}", "exec"), namespace)  # noqa: S102
    finally:
        plt.close("all")
    for name in re.findall(r"""(?:to_csv|savefig)\(\s*["']([^"']+)["']""", code):
        assert (tmp_path / name).is_file(), f"{page}:{line} did not write {name}"
        if Path(name).name == "frf.csv":
            assert tuple(read_csv(tmp_path / name))[: len(FRF_COLUMNS)] == FRF_COLUMNS, f"{page}:{line}: {name}"
    if "sp.kind" in code:  # docs/python.md's first block prints the folds of the bent resonance
        assert "fold" in out.getvalue()
