"""Numbers in the documentation that come from results files, and the check that they agree.

A number the code computes is quoted in README.md and docs/*.md with a **tag** right after it, an
HTML comment that GitHub does not show::

    ID1's driving shaft peaks at 19.4<!--=response/stable/outputs/ID1.driving_shaft.torque/peak *1e-3--> kN m

The tag names a results file and a path inside it: ``response`` is ``docs/results/response.json``
(written by a script under ``scripts/``, listed in ``scripts/regenerate_docs_results.py``), the
next parts are keys (or list indices) separated by ``/``.  Two more sources: ``calibrated`` and
``estimate`` are the parameter files ``assets/parameters/*.toml`` (``calibrated/gear_ratio``).
After the path, optional words:

* ``*F`` — multiply the value by F before comparing (``*1e-3`` for kN m, ``*100`` for %);
* ``abs`` — compare the magnitude;
* ``max`` / ``min`` — the quoted number is an upper / lower bound ("within 0.05 %"), not a
  rounding of the value.

The quoted number agrees when it is the value rounded to the digits quoted: ``4.2·10¹⁵`` stands
for 4.15…4.25·10¹⁵, ``19 411`` for 19 410.5…19 411.5, a bare power ``10²²`` for any value whose
decimal logarithm rounds to 22.  Formats: ``−1.5``, ``+33.27``, ``±0.84``, ``1 138`` (a space
between thousands), ``2.28·10⁴``, ``5.4e-7``, ``10¹⁵``.

A **block** is a whole fragment (a table) that a script rendered; the page holds it between
``<!--begin=PATH-->`` and ``<!--end-->`` and it must equal the string at PATH.

    .venv/bin/python scripts/docs_numbers.py            # list the disagreements (exit 1 if any)
    .venv/bin/python scripts/docs_numbers.py --update   # rewrite every tagged number and block
                                                        # from the results (bounds are listed)

``tests/docs/test_numbers.py`` runs the check.  Every results file records the hash of the
parameter set it was computed on (``parameters_hash``); a file of another set than the bundled
default is a disagreement too.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"
PARAMETER_SOURCES = {"calibrated": ROOT / "assets" / "parameters" / "calibrated.toml",
                     "estimate": ROOT / "assets" / "parameters" / "estimate.toml"}

TAG = re.compile(r"<!--=(?P<ref>[^<>]*?)-->")
BLOCK = re.compile(r"<!--begin=(?P<ref>[^<>]*?)-->\n(?P<body>.*?)<!--end-->", re.S)
SUPERSCRIPT = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺", "0123456789-+")
TO_SUPERSCRIPT = str.maketrans("0123456789-+", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺")
MINUS = "−"  # U+2212, the minus sign of the pages
# a number at the end of the text before a tag: sign, mantissa (thousands grouped by a space or
# not), an exponent ·10ⁿ or eN; or a bare power of ten 10ⁿ
NUMBER = re.compile(
    r"(?:(?P<sign>[+\-−±]?)"
    r"(?P<mantissa>[0-9]{1,3}(?: [0-9]{3})+(?:\.[0-9]+)?|[0-9]+(?:\.[0-9]+)?)"
    r"(?:(?P<dot>·|×)10(?P<sup>[⁻⁺]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+)|[eE](?P<e>[+\-−]?[0-9]+))?"
    r"|(?P<power_sign>[+\-−]?)10(?P<power>[⁻⁺]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+))$")
MODIFIERS = ("abs", "max", "min")


def pages(root: Path = ROOT) -> list[Path]:
    """The pages whose numbers are checked: README.md, docs/*.md, BENCHMARKS.md."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md")), root / "BENCHMARKS.md"]


def parameters_hash() -> str:
    """Hash of the bundled default parameter set (``model.mechanics.parameters.parameter_hash``)."""
    sys.path.insert(0, str(ROOT))
    from model.mechanics.parameters import load_parameters, parameter_hash
    return parameter_hash(load_parameters())


def write_results(name: str, data: dict, command: str) -> Path:
    """Write ``docs/results/NAME.json``: ``data`` with the command that wrote it and the hash of
    the default parameter set (the pages' numbers are of that set)."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.json"
    content = {"command": command, "parameters_hash": parameters_hash(), **data}
    path.write_text(json.dumps(content, indent=1, ensure_ascii=False, allow_nan=False) + "\n",
                    encoding="utf-8")
    return path


# --- quoted numbers -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Quoted:
    """A number as written in a page."""

    text: str  # as written
    value: float  # what it stands for
    unit: float  # one unit of its last quoted digit (for a bare power of ten: nan)
    power: int | None  # the exponent of a bare power of ten, else None

    def agrees(self, value: float, bound: str | None = None) -> bool:
        if not math.isfinite(value):
            return False
        if self.power is not None:
            if value == 0:
                return False
            return (round(math.log10(abs(value))) == self.power
                    and (math.copysign(1.0, value) == math.copysign(1.0, self.value)
                         or self.text.lstrip("~").startswith("10")))
        slack = 0.5 * self.unit * (1 + 1e-9) + 1e-12 * abs(self.value)
        if bound == "max":
            return value <= self.value + slack
        if bound == "min":
            return value >= self.value - slack
        return abs(value - self.value) <= slack


def parse_quoted(before: str) -> tuple[Quoted, re.Match] | None:
    """The number at the end of ``before`` (the text up to a tag), or None."""
    match = NUMBER.search(before)
    if match is None:
        return None
    if match["power"] is not None:
        exponent = int(match["power"].translate(SUPERSCRIPT))
        sign = -1.0 if match["power_sign"] in ("-", MINUS) else 1.0
        return Quoted(match[0], sign * 10.0 ** exponent, math.nan, exponent), match
    mantissa = match["mantissa"].replace(" ", "")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    if match["sup"] is not None:
        exponent = int(match["sup"].translate(SUPERSCRIPT))
    elif match["e"] is not None:
        exponent = int(match["e"].replace(MINUS, "-"))
    else:
        exponent = 0
    sign = -1.0 if match["sign"] in ("-", MINUS) else 1.0
    value = sign * float(mantissa) * 10.0 ** exponent
    return Quoted(match[0], value, 10.0 ** (exponent - decimals), None), match


def format_like(quoted: str, value: float) -> str:
    """``value`` written as ``quoted`` is written: the same digits after the point, exponent
    style, thousands separator and sign convention."""
    match = NUMBER.fullmatch(quoted)
    if match is None:
        raise ValueError(f"not a quoted number: {quoted!r}")
    if match["power"] is not None:
        exponent = round(math.log10(abs(value))) if value else 0
        sign = MINUS if value < 0 else ""
        return f"{sign}10{str(exponent).translate(TO_SUPERSCRIPT)}"
    sign_text = match["sign"]
    mantissa = match["mantissa"]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    grouped = " " in mantissa
    magnitude = abs(value) if sign_text == "±" else value
    if match["sup"] is not None or match["e"] is not None:
        exponent = math.floor(math.log10(abs(magnitude))) if magnitude else 0
        digits = f"{abs(magnitude) / 10.0 ** exponent:.{decimals}f}"
        if float(digits) >= 10:  # 9.96 → 10.0: one more power
            exponent += 1
            digits = f"{abs(magnitude) / 10.0 ** exponent:.{decimals}f}"
        if match["sup"] is not None:
            tail = f"{match['dot']}10{str(exponent).translate(TO_SUPERSCRIPT)}"
        else:
            e_sign = "-" if exponent < 0 else ("+" if match["e"].startswith("+") else "")
            width = len(match["e"].lstrip("+-−"))
            tail = quoted[match.start("e") - 1] + f"{e_sign}{abs(exponent):0{width}d}"
    else:
        digits = f"{abs(magnitude):.{decimals}f}"
        tail = ""
        if grouped:
            whole, _, fraction = digits.partition(".")
            groups = []
            while len(whole) > 3:
                groups.insert(0, whole[-3:])
                whole = whole[:-3]
            digits = " ".join([whole, *groups]) + (f".{fraction}" if fraction else "")
    if sign_text == "±":
        sign = "±"
    elif magnitude < 0 and float(digits.replace(" ", "")) != 0:
        sign = "-" if sign_text == "-" else MINUS
    elif sign_text == "+":
        sign = "+"
    else:
        sign = ""
    return sign + digits + tail


# --- the results ----------------------------------------------------------------------------------

class Sources:
    """Results files and parameter files, read once."""

    def __init__(self, results: Path = RESULTS):
        self.results = results
        self._loaded: dict[str, object] = {}

    def document(self, name: str):
        if name not in self._loaded:
            if name in PARAMETER_SOURCES:
                table = tomllib.loads(PARAMETER_SOURCES[name].read_text(encoding="utf-8"))
                self._loaded[name] = {k: v["value"] for k, v in table.items()}
            else:
                path = self.results / f"{name}.json"
                if not path.is_file():
                    raise LookupError(f"no results file docs/results/{name}.json")
                self._loaded[name] = json.loads(path.read_text(encoding="utf-8"))
        return self._loaded[name]

    def lookup(self, path: str):
        name, *keys = path.split("/")
        node = self.document(name)
        for key in keys:
            if isinstance(node, list):
                try:
                    node = node[int(key)]
                except (ValueError, IndexError):
                    raise LookupError(f"{path}: no item {key!r}") from None
            elif isinstance(node, dict) and key in node:
                node = node[key]
            else:
                raise LookupError(f"{path}: no key {key!r}")
        return node

    def files(self) -> list[str]:
        return sorted(p.stem for p in self.results.glob("*.json"))


@dataclass(frozen=True)
class Reference:
    path: str
    scale: float = 1.0
    magnitude: bool = False
    bound: str | None = None

    @classmethod
    def parse(cls, text: str) -> Reference:
        """``PATH [*F] [abs] [max|min]`` (keys of a path hold no spaces)."""
        path, *words = text.split()
        scale, magnitude, bound = 1.0, False, None
        for word in words:
            if word.startswith("*"):
                scale = float(word[1:])
            elif word == "abs":
                magnitude = True
            elif word in ("max", "min"):
                bound = word
            else:
                raise ValueError(f"unknown word {word!r} in tag {text!r} (known: *F, {MODIFIERS})")
        return cls(path, scale, magnitude, bound)

    def value(self, sources: Sources) -> float:
        raw = sources.lookup(self.path)
        if isinstance(raw, bool) or not isinstance(raw, int | float):
            raise LookupError(f"{self.path} is {raw!r}, not a number")
        value = float(raw) * self.scale
        return abs(value) if self.magnitude else value


@dataclass(frozen=True)
class Disagreement:
    page: str
    line: int
    tag: str
    quoted: str
    expected: str  # what the results say (formatted as quoted, or the reason)

    def __str__(self) -> str:
        return f"{self.page}:{self.line}: {self.quoted!r} <!--={self.tag}--> → {self.expected}"


def _line_of(text: str, index: int) -> int:
    return text.count("\n", 0, index) + 1


def check_text(text: str, page: str, sources: Sources, update: bool = False
               ) -> tuple[list[Disagreement], str, int]:
    """(disagreements, the text with tagged numbers and blocks rewritten if ``update``, the
    count of tags and blocks checked)."""
    found: list[Disagreement] = []
    pieces: list[str] = []
    position = 0
    count = 0
    for block in BLOCK.finditer(text):
        count += 1
        line = _line_of(text, block.start())
        try:
            expected = sources.lookup(block["ref"])
        except LookupError as error:
            found.append(Disagreement(page, line, block["ref"], "(block)", str(error)))
            continue
        if not isinstance(expected, str):
            found.append(Disagreement(page, line, block["ref"], "(block)", "not a text"))
            continue
        differs = block["body"].strip("\n") != expected.strip("\n")
        if differs or not block["body"].endswith("\n"):  # <!--end--> on a line of its own
            found.append(Disagreement(page, line, block["ref"], "(block)",
                                      "the results' text differs" if differs else
                                      "<!--end--> must start a line (after a table or a code fence)"))
            if update:
                pieces.append(text[position:block.start("body")] + expected.strip("\n") + "\n")
                position = block.end("body")
    pieces.append(text[position:])
    text = "".join(pieces)
    pieces, position = [], 0
    for tag in TAG.finditer(text):
        count += 1
        line = _line_of(text, tag.start())
        parsed = parse_quoted(text[max(0, tag.start() - 40):tag.start()])
        if parsed is None:
            found.append(Disagreement(page, line, tag["ref"], text[max(0, tag.start() - 12):tag.start()],
                                      "no number right before the tag"))
            continue
        quoted, _ = parsed
        try:
            reference = Reference.parse(tag["ref"])
            value = reference.value(sources)
        except (LookupError, ValueError) as error:
            found.append(Disagreement(page, line, tag["ref"], quoted.text, str(error)))
            continue
        if quoted.agrees(value, reference.bound):
            continue
        if reference.bound:
            found.append(Disagreement(page, line, tag["ref"], quoted.text,
                                      f"{value:.6g} is not {'≤' if reference.bound == 'max' else '≥'} it"))
            continue
        new = format_like(quoted.text, value)
        found.append(Disagreement(page, line, tag["ref"], quoted.text, f"{new} ({value:.6g})"))
        if update:
            start = tag.start() - len(quoted.text)
            pieces.append(text[position:start] + new)
            position = tag.start()
    pieces.append(text[position:])
    return found, "".join(pieces), count


def check_pages(root: Path = ROOT, update: bool = False, results: Path = RESULTS
                ) -> tuple[list[Disagreement], int]:
    """Check (and with ``update`` rewrite) every page; also every results file's parameter hash."""
    sources = Sources(results)
    found: list[Disagreement] = []
    count = 0
    for page in pages(root):
        text = page.read_text(encoding="utf-8")
        disagreements, new_text, n = check_text(text, page.relative_to(root).as_posix(), sources, update)
        found += disagreements
        count += n
        if update and new_text != text:
            page.write_text(new_text, encoding="utf-8")
    current = parameters_hash()
    for name in sources.files():
        recorded = sources.document(name).get("parameters_hash")
        if recorded != current:
            found.append(Disagreement(f"docs/results/{name}.json", 1, f"{name}/parameters_hash",
                                      str(recorded)[:12], f"computed on another parameter set than "
                                      f"the bundled one ({current[:12]}…): regenerate it"))
    return found, count


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", action="store_true",
                        help="rewrite every tagged number and block from the results files")
    args = parser.parse_args(argv)
    found, count = check_pages(update=args.update)
    for item in found:
        print(item)
    verb = "rewritten" if args.update else "found"
    print(f"{count} tagged numbers and blocks; {len(found)} disagreements {verb}")
    if args.update:
        remaining, _ = check_pages()
        print(f"{len(remaining)} disagreements remain (bounds, missing keys: edit the page)")
        return 1 if remaining else 0
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
