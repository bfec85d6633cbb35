"""The product speaks of the software, not of how it was made: no rounds or sessions of work,
issue numbers, "tried and not kept", commit references, dates of work, internal paths of the
project's working notes, in the pages (README.md, docs/, BENCHMARKS.md), in the comments and
docstrings of the source (model/, app/, scripts/, tests/) and in pyproject.toml.  And every file a
page or a comment names (``tests/…py``, ``scripts/…py``, ``docs/….md``, ``model/…py``,
``app/…py``) exists.

The count of findings is the measure (target 0).  The patterns are precise on purpose: "session"
alone is a dashboard session, "round" alone rounds numbers; only the work-history uses match."""

from __future__ import annotations

import re

import pytest
from conftest import ROOT, bogie_parsers

THIS = "tests/docs/test_wording.py"
_ORDINAL = r"(?:first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|this|last|previous|earlier|next)"
HISTORY = {
    "issue number": r"\b[Ii]ssues?\s*#?\d+|\bissue\d+",
    # "this session", "a second session" are dashboard sessions; the work history numbers them
    "work session": r"\b(?:third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|last|earlier)\s+sessions?\b"
                    r"|\bwork(?:ing)?\s+session|\bsessions of work",
    "round of work": rf"\b{_ORDINAL}\s+round\b|\brounds? of work|\bafter this round|\bin this round",
    "tried, not kept": r"\b[Tt]ried(?:,| and)? (?:not kept|rejected|dropped)|\bmeasured, not kept",
    "for the record": r"\bfor the record\b",
    "commit reference": r"\bcommits?\s+[0-9a-f]{7,40}\b",
    "the lead": r"\bthe lead(?: engineer)?\b(?! screw)",
    "the issue": r"\b(?:this|the) issue(?:'s)?\b",
    "date of work": r"\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b",
    "working notes": r"shared/spec|shared/guide|/work/shared|\.\./shared|docs/attempts",
    "a helper": r"\b(?:another|other) engineers?\b|\bhelpers?['’] work",
}
PAGES = [ROOT / "README.md", ROOT / "BENCHMARKS.md", *sorted((ROOT / "docs").glob("*.md"))]
SOURCES = [p for folder in ("model", "app", "scripts", "tests") for p in sorted((ROOT / folder).rglob("*.py"))]
ALLOWED_DATES = {"BENCHMARKS.md"}  # the reference dates each measurement; nothing else does
EXAMPLES = {"docs/results/NAME.json", "docs/results/x.json", "model/wing/long.py"}  # not files
PATH = re.compile(r"(?<![\w/.-])((?:tests|scripts|docs|model|app)/[\w/.*-]+\.(?:py|md|toml|json|sh))")


def findings(text: str, name: str) -> list[str]:
    found = []
    for label, pattern in HISTORY.items():
        if label == "date of work" and name in ALLOWED_DATES:
            continue
        for match in re.finditer(pattern, text):
            line = text.count("\n", 0, match.start()) + 1
            found.append(f"{name}:{line}: {label}: {match.group(0)!r}")
    return found


def _files():
    for path in [*PAGES, *SOURCES, ROOT / "pyproject.toml"]:
        relative = path.relative_to(ROOT).as_posix()
        if relative != THIS:
            yield relative, path.read_text(encoding="utf-8")


def test_no_history_words_in_pages_source_comments_and_pyproject():
    found = [item for name, text in _files() for item in findings(text, name)]
    assert found == [], f"{len(found)} history words:\n" + "\n".join(found)


def test_every_named_file_exists():
    missing = []
    for name, text in _files():
        for match in PATH.finditer(text):
            target = match.group(1).rstrip(".")
            if target in EXAMPLES:
                continue
            if "*" in target:
                ok = any(ROOT.glob(target))
            else:
                ok = (ROOT / target).exists()
            if not ok:
                missing.append(f"{name}: {target}")
    assert missing == [], f"{len(missing)} dead paths:\n" + "\n".join(missing)


TEST_NAME = re.compile(r"\b(test_[a-z0-9_]+)\b")


def test_every_named_test_exists():
    """A test a page names (``test_…``: a test function or a test module) is in tests/."""
    defined = set()
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        defined.add(path.stem)
        defined |= set(re.findall(r"^\s*def (test_\w+)", path.read_text(encoding="utf-8"), re.M))
    missing = [f"{page.relative_to(ROOT).as_posix()}: {name}" for page in PAGES
               for name in TEST_NAME.findall(page.read_text(encoding="utf-8"))
               if name not in defined and not name.endswith("_")]
    assert missing == [], f"{len(missing)} tests named but not defined:\n" + "\n".join(missing)


OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]+)")
EXTERNAL = {  # options of other programs the pages show (pip, docker, dask, pytest, buildah …)
    "--rm", "--build-arg", "--network", "--no-dashboard", "--nworkers", "--nthreads", "--host",
    "--isolation", "--variant", "--include", "--durations", "--dist", "--liveness", "--no-sandbox",
    "--headless", "--disable-gpu", "--disable-quic", "--no-first-run", "--user-data-dir",
    "--disable-background-networking", "--disable-component-update", "--disable-sync", "--strict-markers",
    "--strict-config", "--port", "--address", "--allow-websocket-origin", "--help", "--version",
    "--stat", "--threads", "--project", "--rate", "--quiet", "--local-directory", "--nanny-port",
    "--tls-ca-file", "--worker-port",
}
COMMENT = re.compile(r"<!--.*?-->", re.S)


def parser_options() -> set[str]:
    """Every option string of ``bogie``'s parser and its sub-commands'."""
    return {o for _, parser in bogie_parsers() for action in parser._actions
            for o in action.option_strings if o.startswith("--")}


def test_every_option_a_page_names_exists():
    """An option a page names (``--something``) is one of ``bogie``'s (its commands' own or a
    case quantity's, declared in app/results/case.py), a script's, ``run.sh``'s, or one of
    another program's the pages show (EXTERNAL)."""
    sources = [*sorted((ROOT / "app" / "cli").glob("*.py")), ROOT / "app" / "results" / "case.py",
               *sorted((ROOT / "scripts").glob("*.py")),
               ROOT / "run.sh", ROOT / "scripts" / "build_image.sh", ROOT / "app" / "server" / "serve.py"]
    known = set(EXTERNAL)
    for path in sources:
        known |= set(re.findall(r"[\"'](--[a-z][a-z0-9-]+)", path.read_text(encoding="utf-8")))
        if path.suffix == ".sh":
            known |= set(OPTION.findall(path.read_text(encoding="utf-8")))
    known |= parser_options()  # the parser's own (``--no-X`` of a yes/no option included)
    missing = sorted({f"{page.relative_to(ROOT).as_posix()}: {option}" for page in PAGES
                      for option in OPTION.findall(COMMENT.sub("", page.read_text(encoding="utf-8")))
                      if option not in known})
    assert missing == [], f"{len(missing)} options named but not defined:\n" + "\n".join(missing)


@pytest.mark.parametrize(("text", "label"), [
    ("measured in the seventh session's run", "work session"),
    ("on the machines of the earlier sessions", "work session"),
    ("see issue 13 and issue #27", "issue number"),
    ("Tried and rejected: a looser cut-off", "tried, not kept"),
    ("a variant, tried, not kept", "tried, not kept"),
    ("after this round the slider", "round of work"),
    ("commit 003ef02 gave", "commit reference"),
    ("re-quoted on 2026-12-03", "date of work"),
    ("`shared/spec/model.md` §4", "working notes"),
    ("the lead re-measures", "the lead"),
])
def test_the_patterns_find_history(text, label):
    assert {f.split(": ")[1] for f in findings(text, "x.md")} == {label}


@pytest.mark.parametrize("text", [
    "one study per session", "each session has its own dashboard", "the session's document lock",
    "this session's study is still waiting", "a second session's study waits",
    "or None if that sweep's start is not kept",
    "rounding-level wiggles", "round(t_end·fs)", "a stick–slip cycle round the creep maximum",
    "the previous valid state kept", "log₂ 32 = 5 doubling steps", "a known issue of SciPy",
])
def test_legitimate_uses_are_not_flagged(text):
    assert findings(text, "x.md") == []
