"""The documentation pages: every figure exists, and the command beside it reproduces it.

A figure on a page (``![...](figures/x.png)`` in ``docs/*.md``) must have, in its own paragraph
or the caption paragraph after it, the command that draws it: ``python examples/<script>.py
…`` or ``rollqp run <scene> …``. The command must name an existing script (whose argument
parser accepts the options used) or an existing scene, and must write *this* figure: its
``--figure``/``--plot`` path is the image's path, or its ``--figures`` folder the image's
folder. Every image in ``docs/figures`` must be shown on some page. The examples themselves
are run by tests/test_examples.py and tests/test_paper_examples.py; the HTML build
(``docs/build.sh``, Sphinx with warnings as errors) is run by CI.
"""
from __future__ import annotations

import contextlib
import io
import re
import runpy
import shlex
from pathlib import Path

import pytest

import rollqp
from rollqp import cli

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")
COMMAND = re.compile(r"`((?:python (?:examples|benchmarks)/|rollqp run |rollqp bench |rollqp creep-curve |rollqp stresses )[^`]+)`")


def _figures():
    """``(page, image path relative to docs/, the text beside it)`` for every image on every page."""
    out = []
    for page in PAGES:
        paragraphs = re.split(r"\n\s*\n", page.read_text(encoding="utf-8"))
        for k, par in enumerate(paragraphs):
            for target in IMAGE.findall(par):
                beside = par + "\n" + (paragraphs[k + 1] if k + 1 < len(paragraphs) else "")
                out.append((page.name, target, beside))
    return out


FIGURES = _figures()


def _options(argv):
    return {a.split("=")[0] for a in argv if a.startswith("--")}


def _script_options(script):
    """The options the script's argument parser knows (from its ``--help``)."""
    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out):
        mp.setattr("sys.argv", [str(script), "--help"])
        mp.syspath_prepend(str(script.parent))   # as `python benchmarks/x.py` does (harness.py beside it)
        with pytest.raises(SystemExit):
            runpy.run_path(str(script), run_name="__main__")
    return set(re.findall(r"--[a-z][a-z-]*", out.getvalue()))


def _cli_options(subcommand):
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        cli.main([subcommand, "--help"])
    return set(re.findall(r"--[a-z][a-z-]*", out.getvalue()))


def _bench_options():
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        cli.main(["bench", "--help"])
    return set(re.findall(r"--[a-z][a-z-]*", out.getvalue()))


def test_pages_have_figures():
    assert len(FIGURES) >= 13, f"the gallery's figures are found: {[f for _, f, _ in FIGURES]}"


@pytest.mark.parametrize("page, target", [(p, t) for p, t, _ in FIGURES], ids=[t for _, t, _ in FIGURES])
def test_figure_exists(page, target):
    path = (DOCS / target).resolve()
    assert path.is_file(), f"{page}: image {target} does not exist"
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{page}: {target} is not a PNG"


@pytest.mark.parametrize("page, target, beside", FIGURES, ids=[t for _, t, _ in FIGURES])
def test_figure_has_its_command_beside_it(page, target, beside):
    commands = [shlex.split(c) for c in COMMAND.findall(beside)]
    assert commands, f"{page}: no `python examples/…`, `python benchmarks/…` or `rollqp run …` command beside {target}"
    image = Path("docs") / target
    writes = []
    for argv in commands:
        if argv[0] == "python":
            script = ROOT / argv[1]
            assert script.is_file(), f"{page}: {argv[1]} (beside {target}) does not exist"
            unknown = _options(argv[2:]) - _script_options(script)
            assert not unknown, f"{page}: {argv[1]} does not accept {sorted(unknown)}"
        elif argv[1] == "bench":
            unknown = _options(argv[2:]) - _bench_options()
            assert not unknown, f"{page}: rollqp bench does not accept {sorted(unknown)}"
        else:
            scene = argv[2]
            assert argv[1] == "stresses" or scene in rollqp.builtin_scenes() or (ROOT / scene).is_file(), \
                f"{page}: scene {scene!r} (beside {target}) is neither built in nor a file"   # stresses: a result
            unknown = _options(argv[3:]) - _cli_options(argv[1])
            assert not unknown, f"{page}: rollqp {argv[1]} does not accept {sorted(unknown)}"
        for opt, value in zip(argv, argv[1:]):
            if opt in ("--figure", "--plot", "--mesh"):
                writes.append(Path(value) == image)
            elif opt == "--figures":
                writes.append(Path(value) == image.parent)
    assert any(writes), f"{page}: no command beside {target} writes it ({[' '.join(c) for c in commands]})"


def test_every_figure_file_is_shown():
    shown = {(DOCS / t).resolve() for _, t, _ in FIGURES}
    files = {p.resolve() for p in (DOCS / "figures").glob("*.png")}
    assert files - shown == set(), f"figures no page shows (and so no command documents): {sorted(files - shown)}"


def test_build_script_is_the_documented_command():
    script = (DOCS / "build.sh").read_text(encoding="utf-8")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    command = "python -m sphinx -W --keep-going -b html docs docs/_build/html"
    assert command in script and command in readme, "docs/build.sh runs the command the README shows"


def test_every_quoted_command_names_an_existing_script_or_scene():
    """Anywhere on the pages and in the README, not only beside figures: no stale commands."""
    scripts = re.compile(r"python ((?:examples|benchmarks)/[A-Za-z0-9_./-]+\.py)")
    runs = re.compile(r"rollqp run ([a-z0-9_./][a-z0-9_./-]*)")  # lower case: SCENE and … are placeholders; options skipped
    for page in [*PAGES, ROOT / "README.md"]:
        text = page.read_text(encoding="utf-8")
        for script in scripts.findall(text):
            assert (ROOT / script).is_file(), f"{page.name}: {script} does not exist"
        for scene in runs.findall(text):
            assert scene in rollqp.builtin_scenes() or (ROOT / scene).is_file(), \
                f"{page.name}: `rollqp run {scene}`: no such built-in scene or file"


def test_result_file_reference_is_the_field_registry():
    """docs/results.md's table is generated from rollqp.fields (regenerate it with
    ``rollqp.fields.markdown_table()`` after adding a field)."""
    from rollqp.fields import markdown_table
    text = (DOCS / "results.md").read_text(encoding="utf-8")
    table = text.split("<!-- fields table: begin -->\n", 1)[1].split("<!-- fields table: end -->", 1)[0]
    assert table.strip() == markdown_table().strip(), "docs/results.md is stale: paste rollqp.fields.markdown_table()"


def test_scene_reference_lists_every_key():
    """docs/scenes.md documents every key a scene file accepts."""
    import dataclasses
    from rollqp.scene import Body, Contact, Discretization, Load, SolverSettings
    text = (DOCS / "scenes.md").read_text(encoding="utf-8")
    keys = [f"bodies.A.{f.name}" for f in dataclasses.fields(Body)]
    keys += [f"{sec}.{f.name}" for sec, cls in (("contact", Contact), ("load", Load),
                                               ("discretization", Discretization), ("solver", SolverSettings))
             for f in dataclasses.fields(cls)]
    missing = [k for k in keys + ["name", "description"] if f"`{k}`" not in text]
    assert not missing, f"docs/scenes.md does not document {missing}"


def test_readme_snippet_runs():
    """The README's one-step snippet is complete: it runs as written and its two QP backends agree."""
    import contextlib
    import io
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## One step from your own arrays", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    out = io.StringIO()
    scope = {}
    with contextlib.redirect_stdout(out):
        exec(compile(block, "README.md", "exec"), scope)  # noqa: S102 - the project's own README
    diff = rollqp.compare(scope["a"], scope["b"], mu=scope["mu"], scales=scope["scales"])
    # constant elements: F·A exactly symmetric, both backends solve the same QP to 5e-9 (conftest.BACKENDS)
    assert diff["t"] <= 1e-8 and scope["a"].residual <= 1e-8, out.getvalue()


def test_every_cited_formulation_section_exists():
    """Code, docs, tests, examples and benchmarks cite the equations as ``docs/formulation.md §N``
    (the one source): every cited N must be a numbered section of that page."""
    page = (ROOT / "docs" / "formulation.md").read_text(encoding="utf-8")
    sections = set(re.findall(r"^## (\d+)\. ", page, flags=re.M))
    cited = {}
    for folder in ("rollqp", "docs", "tests", "examples", "benchmarks"):
        for path in sorted((ROOT / folder).rglob("*")):
            if path.suffix not in (".py", ".md") or "_build" in path.parts:
                continue
            for n in re.findall(r"formulation\.md ?§ ?(\d+)", path.read_text(encoding="utf-8")):
                cited.setdefault(n, path.relative_to(ROOT))
    missing = {n: str(p) for n, p in cited.items() if n not in sections}
    assert cited and not missing, f"cited sections that docs/formulation.md does not have: {missing}"


def test_index_lists_every_page():
    """docs/index.md names every page with a link (one line each), so the docs read as one book."""
    text = (DOCS / "index.md").read_text(encoding="utf-8")
    linked = set(re.findall(r"\]\(([\w.-]+\.md)\)", text))
    missing = sorted(p.name for p in PAGES if p.name != "index.md" and p.name not in linked)
    assert not missing, f"docs/index.md does not list {missing}"


def test_no_internal_issue_numbers():
    """Docs and code speak of the project, never of its tracker: no "issue N" anywhere users read
    (the package, its docs, and the tests' and benchmarks' text, which the docs cite)."""
    found = []
    code = [p for d in ("rollqp", "benchmarks", "tests") for p in sorted((ROOT / d).rglob("*.py"))]
    for path in [ROOT / "README.md", *PAGES, *code]:
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if re.search(r"[Ii]ssues? [0-9]+|\b[Tt]he issue'?s?\b", line):
                found.append(f"{path.relative_to(ROOT)}:{n}")
    assert not found, found
