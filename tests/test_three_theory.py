"""docs/theory3d.md defines every equation it numbers, once and in order, and every citation of a 3D
equation anywhere in the repository (code, docs, tests, benchmarks) names one that it defines; each is
cited by the code that computes it. Dundurs' β of the 3D constants has the body order the page states."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from rollqp.materials import Materials

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "theory3d.md"
#: A defined equation: a display line ending in its label.
DEFINED = re.compile(r"\(3D\.(\d+)\)\s*$")
CITED = re.compile(r"3D\.(\d+)\b")


def _defined() -> list[int]:
    return [int(m.group(1)) for line in PAGE.read_text(encoding="utf-8").splitlines()
            if (m := DEFINED.search(line))]


def _sources():
    for folder in ("rollqp", "docs", "tests", "benchmarks", "examples"):
        for path in (ROOT / folder).rglob("*"):
            if path.suffix in (".py", ".md", ".toml") and path.is_file():
                yield path


def test_every_numbered_equation_is_defined_once_and_in_order():
    defs = _defined()
    assert defs == list(range(1, len(defs) + 1)), f"theory3d.md defines {defs}"
    assert len(defs) >= 29


def test_every_citation_names_a_defined_equation():
    n = len(_defined())
    bad = [(str(p.relative_to(ROOT)), int(m.group(1))) for p in _sources()
           for m in CITED.finditer(p.read_text(encoding="utf-8")) if not 1 <= int(m.group(1)) <= n]
    assert not bad, f"citations of equations theory3d.md does not define: {bad}"


def test_every_equation_is_cited_by_the_code():
    """Each (3D.N) is cited in rollqp/ (a docstring where the code computes it; a range 3D.a–3D.b cites both
    ends and what lies between)."""
    code = "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "rollqp").rglob("*.py"))
    cited = {int(m.group(1)) for m in CITED.finditer(code)}
    for a, b in re.findall(r"3D\.(\d+)–3D\.(\d+)", code):
        cited |= set(range(int(a), int(b) + 1))
    missing = sorted(set(_defined()) - cited)
    assert not missing, f"equations no code cites: {missing}"


@pytest.mark.parametrize("A, B", [((70e3, 0.33), (210e3, 0.28)), ((210e3, 0.28), (70e3, 0.33)),
                                  ((5e3, 0.45), (210e3, 0.3))])
def test_dundurs_beta_has_body_1_a(A, B):
    """Dundurs' β = ½[(1−2ν₁)/G₁ − (1−2ν₂)/G₂]/[(1−ν₁)/G₁ + (1−ν₂)/G₂] with body 1 = A is K/(1 − ν) (eq. 3D.10):
    positive for the softer A (aluminium on steel), negative swapped."""
    (EA, nA), (EB, nB) = A, B
    GA, GB = EA / (2 * (1 + nA)), EB / (2 * (1 + nB))
    dundurs = 0.5 * ((1 - 2 * nA) / GA - (1 - 2 * nB) / GB) / ((1 - nA) / GA + (1 - nB) / GB)
    m = Materials.from_young(EA, nA, EB, nB)
    assert m.beta == pytest.approx(dundurs, rel=1e-13) and m.beta == pytest.approx(m.K / (1 - m.nu), rel=1e-13)
    assert (m.beta > 0) == ((1 - 2 * nA) / GA > (1 - 2 * nB) / GB)


#: Phrases that name what an equation is, and its number: a citation carried over from an older numbering
#: is caught here (the numbers are the page's, see test_every_numbered_equation_is_defined_once_and_in_order).
NAMED = [(re.compile(r"residuals? \(eq\. 3D\.(\d+)"), 29), (re.compile(r"\bSOCP of eq\. 3D\.(\d+)"), 20),
         (re.compile(r"\bQP of eq\. 3D\.(\d+)"), 22), (re.compile(r"paraboloids? of eq\. 3D\.(\d+)"), 3),
         (re.compile(r"Kalker's linear (?:law|theory)[^.\n]{0,12}\(?eq\. 3D\.(\d+)"), 8)]


def test_named_citations_have_their_numbers():
    bad = [(str(p.relative_to(ROOT)), m.group(0), n) for p in _sources() for rx, n in NAMED
           for m in rx.finditer(p.read_text(encoding="utf-8")) if int(m.group(1)) != n]
    assert not bad, f"citations whose number is not the equation they name: {bad}"
