"""Every command line and Python example of README.md and docs/*.md runs as written.

Each fenced block tagged ``bash``, ``console`` or ``python`` is run, page by page and in order, in a fresh
folder (one per page, so a block may read what an earlier block of its page wrote; ``src`` there is the
repository's, so the documented ``src/stickslip/data/...`` paths of a clone work).  ``stickslip ...`` lines go
through ``stickslip.cli.main.main`` in this process (as the console script runs it, exit status 0 required),
``python -c`` lines and ``python`` blocks through ``exec``.  Blocks that show rather than run are tagged
``text``, ``json``, ``toml`` or ``csv``; an untagged block, or an indented code block holding a command, fails.

A page steers a block with HTML comments on the lines just before its fence (invisible when rendered):

* ``<!-- test: skip REASON -->``: not run (the reason is required and kept in the test's output);
* ``<!-- test: replace OLD -> NEW -->``: run with OLD replaced by NEW, for shorter runs (OLD must occur);
* ``<!-- test: before COMMAND -->``: a shell line run first, to make the block's input files;
* ``<!-- test: expect TEXT -->`` (repeatable): what the block's commands (or a ``python`` block's ``print``)
  print must contain TEXT — a number the page quotes beside the command comes from that command (a block with
  an ``expect`` runs unshortened).  The text around the numbers must be the same; a number with a decimal point or
  an exponent may differ by ``QUOTED_RTOL`` (a fit's last printed digits move between CPUs: :func:`quoted`),
  an integer not at all.

Inline code that starts with ``stickslip`` (synopses in tables and prose) is checked too: its command must exist
and every ``--option`` in it must be one of that command's.  Every ``stickslip.module.name`` a page mentions must
import, every repository path (``src/...``, ``tests/...``, ``docs/...``) and every relative link must exist.
"""

from __future__ import annotations

import importlib
import pickle
import re
import shlex
import time
from dataclasses import dataclass, field
from pathlib import Path

import click
import pytest

from stickslip.cli.main import cli, main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUNNABLE = {"bash", "console", "python"}
SHOWN = {"text", "json", "toml", "csv", "mermaid"}  # mermaid: the diagram of docs/architecture.md
FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})\s*(?P<lang>[^\s`]*)")
MARKER = re.compile(r"^\s*<!--\s*test:\s*(?P<kind>skip|replace|before|expect)\b\s*(?P<arg>.*?)\s*-->\s*$")
#: nan or inf as a number in an output (not "info", "infinite", "inflection")
NON_FINITE = re.compile(r"(?<![A-Za-z])[-+]?(nan|inf|infinity)(?![A-Za-z])", re.IGNORECASE)
#: a number printed with binary round-off showing (0.00035999999999999997, 10.000000000000002)
FLOAT_NOISE = re.compile(r"(?<![\d.])\d+\.\d*?(?:0{9,}|9{9,})\d+(?:e[-+]?\d+)?")


def float_noise(printed: str) -> list[str]:
    """Numbers in what a command printed for a reader that show float round-off; a CSV line (a trace written to
    standard output) keeps every digit on purpose, so that reading it back gives the same floats."""
    text = "\n".join(line for line in printed.splitlines() if line.count(",") < 3)
    return FLOAT_NOISE.findall(text)


INLINE = re.compile(r"(?<!`)`(stickslip [^`]+)`(?!`)")
TIMES: dict[str, float] = {}


@dataclass
class Block:
    page: Path
    line: int
    lang: str
    text: str
    markers: list[tuple[str, str]] = field(default_factory=list)

    @property
    def where(self) -> str:
        return f"{_page_id(self.page)}:{self.line}"

    def skip_reason(self) -> str | None:
        return next((arg for kind, arg in self.markers if kind == "skip"), None)

    def runnable_text(self) -> str:
        text = self.text
        for kind, arg in self.markers:
            if kind == "replace":
                old, sep, new = arg.partition(" -> ")
                assert sep and old, f"{self.where}: expected `replace OLD -> NEW`, got {arg!r}"
                assert old in text, f"{self.where}: `replace {old}` does not occur in the block"
                text = text.replace(old, new)
        return text


def _page_id(page: Path) -> str:
    return str(page.relative_to(ROOT)) if page.is_relative_to(ROOT) else str(page)


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of a page, each with the test markers just before it."""
    found: list[Block] = []
    lines = page.read_text(encoding="utf-8").splitlines()
    markers: list[tuple[str, str]] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        opening = FENCE.match(line)
        marker = MARKER.match(line)
        if marker:
            markers.append((marker["kind"], marker["arg"]))
        elif opening:
            fence, body, j = opening["fence"], [], i + 1
            while j < len(lines) and not lines[j].strip().startswith(fence):
                body.append(lines[j])
                j += 1
            found.append(Block(page, i + 1, opening["lang"].lower(), "\n".join(body) + "\n", markers))
            markers, i = [], j
        elif line.strip():
            markers = []
        i += 1
    return found


def indented_commands(page: Path) -> list[str]:
    """Indented code blocks (4 spaces after a blank line, outside fences) that hold a command: not tested."""
    hits, in_fence, previous_blank = [], False, True
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            in_fence = not in_fence
        elif not in_fence and previous_blank and re.match(r"^( {4,}|\t)(\$ )?(stickslip|python)\b", line):
            hits.append(f"{_page_id(page)}:{number}: {line.strip()}")
        previous_blank = not line.strip()
    return hits


def shell_lines(text: str, lang: str) -> list[str]:
    """Logical command lines: continuations joined; for ``console`` only the ``$ `` lines."""
    joined = text.replace("\\\n", " ")
    lines = [line.strip() for line in joined.splitlines()]
    if lang == "console":
        return [line[2:] for line in lines if line.startswith("$ ")]
    return [line for line in lines if line and not line.startswith("#")]


def run_shell_line(line: str, where: str, capsys: pytest.CaptureFixture[str]) -> str:
    """Run one logical line (``&&`` chains too); returns what its stickslip commands printed."""
    words = shlex.split(line, comments=True)
    unsupported = {"|", ">", ">>", "<", ";", "||", "&"} & set(words)
    assert not unsupported, f"{where}: cannot run {line!r} (shell operator {unsupported}); mark the block"
    command: list[str] = []
    printed = ""
    for word in [*words, "&&"]:
        if word != "&&":
            command.append(word)
            continue
        if command:
            printed += run_command(command, where, capsys)
        command = []
    return printed


def run_command(argv: list[str], where: str, capsys: pytest.CaptureFixture[str]) -> str:
    program = Path(argv[0]).name
    if program == "stickslip":
        capsys.readouterr()
        with pytest.raises(SystemExit) as exit_info:
            main(argv[1:])
        out, err = capsys.readouterr()
        status = exit_info.value.code or 0
        assert status == 0, f"{where}: `{shlex.join(argv)}` exited {status}:\n{err[-2000:]}\n{out[-1000:]}"
        return out + err
    elif program in {"python", "python3"} and len(argv) == 3 and argv[1] == "-c":
        capsys.readouterr()
        exec(compile(argv[2], where, "exec"), {"__name__": "__main__"})
        out, err = capsys.readouterr()
        return out + err
    else:
        pytest.fail(f"{where}: no runner for `{shlex.join(argv)}`; mark the block (skip REASON) if it is not run")
    return ""


#: a quoted number with a decimal point or an exponent matches the printed one within this relative difference.  The
#: least-squares fits of docs/rsf.md print six digits of parameters known to 10-20 %; their search stops within its
#: tolerance of the minimum, and where it stops moves with the CPU's arithmetic: on an AVX2-only machine Dc printed
#: 64.1521 and 262.581 um against the page's 64.1482 and 262.528 (6e-5, 2e-4), chi-square_r 8.155 against 8.156
QUOTED_RTOL = 1e-3
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def quoted(expected: str, printed: str) -> bool:
    """Whether ``printed`` contains ``expected``: the same text between the numbers, and each number the same (an
    integer) or within QUOTED_RTOL of it (a decimal)."""
    if expected in printed:
        return True
    numbers = NUMBER.findall(expected)
    if not numbers:
        return False
    parts = NUMBER.split(expected)
    pattern = "".join(re.escape(part) + (f"({NUMBER.pattern})" if k < len(numbers) else "") for k, part in
                      enumerate(parts))  # fmt: skip
    for match in re.finditer(pattern, printed):
        pairs = zip(numbers, match.groups(), strict=True)
        if all(
            a == b or (any(c in a for c in ".eE") and abs(float(a) - float(b)) <= QUOTED_RTOL * abs(float(a)))
            for a, b in pairs
        ):
            return True
    return False


def run_block(block: Block, namespace: dict, capsys: pytest.CaptureFixture[str]) -> None:
    for kind, arg in block.markers:
        if kind == "before":
            run_shell_line(arg, f"{block.where} (before)", capsys)
    text = block.runnable_text()
    if block.lang == "python":
        capsys.readouterr()
        exec(compile(text, block.where, "exec"), namespace)
        out, err = capsys.readouterr()
        printed = out + err
    else:
        printed = "".join(run_shell_line(line, block.where, capsys) for line in shell_lines(text, block.lang))
        shown = NON_FINITE.search(printed)  # issue 28: no command prints nan or inf; it says what is unknown
        assert shown is None, f"{block.where}: the output shows {shown.group(0)!r}:\n{printed[-2000:]}"
        noise = float_noise(printed)
        assert not noise, f"{block.where}: the output shows binary float noise {noise[:3]}:\n{printed[-2000:]}"
    missing = [arg for kind, arg in block.markers if kind == "expect" and not quoted(arg, printed)]
    assert not missing, f"{block.where}: the page quotes {missing} beside the command, which printed:\n{printed}"


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_every_block_is_tagged_and_marked_with_reasons(page):
    for block in blocks(page):
        assert block.lang in RUNNABLE | SHOWN, (
            f"{block.where}: a fenced block must say what it is (```bash, ```python, ```text, ...), got {block.lang!r}"
        )
        reason = block.skip_reason()
        assert reason is None or len(reason) > 10, f"{block.where}: `test: skip` needs its reason"
        block.runnable_text()  # every replace marker applies
        kinds = {kind for kind, _ in block.markers}
        assert not {"expect", "replace"} <= kinds, f"{block.where}: a quoted number comes from the command as shown"
    assert not indented_commands(page), "commands in indented blocks are not tested; fence them:\n" + "\n".join(
        indented_commands(page)
    )


#: rate-and-state fits already made in this process, by their record and settings (see _fit_once)
_RSF_FITS: dict[bytes, object] = {}


def _fit_once(compute):
    """stickslip.rsf.fit.fit_record, made once per record and settings: the pages fit the shipped sepiolite step
    with --trend three times (README.md, and docs/rsf.md in its table and its command line: ~2.5 s each).  The
    fit is a function of its record and settings (both in the key, the record's source path included), so each
    command gets the fit it would compute and still reads its file, reports and writes its outputs itself."""

    def fit_record(record, **settings):
        key = pickle.dumps((record, settings))
        if key not in _RSF_FITS:
            _RSF_FITS[key] = compute(record, **settings)
        return _RSF_FITS[key]

    return fit_record


@pytest.mark.parametrize("page", [p for p in PAGES if any(b.lang in RUNNABLE for b in blocks(p))], ids=_page_id)
def test_documented_commands_and_examples_run(page, tmp_path, monkeypatch, capsys):
    from stickslip.rsf import fit as rsf_fit

    runnable = [b for b in blocks(page) if b.lang in RUNNABLE]
    monkeypatch.setattr(rsf_fit, "fit_record", _fit_once(rsf_fit.fit_record))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    namespace: dict = {"__name__": "__main__"}
    started, skipped = time.perf_counter(), []
    for block in runnable:
        if block.skip_reason():
            skipped.append(f"{block.where}: {block.skip_reason()}")
            continue
        run_block(block, namespace, capsys)
    TIMES[_page_id(page)] = time.perf_counter() - started
    with capsys.disabled():
        print(f"\n{_page_id(page)}: {TIMES[_page_id(page)]:.1f} s" + "".join(f"\n  skipped {s}" for s in skipped))


def _commands() -> dict[str, click.Command]:
    found: dict[str, click.Command] = {}

    def walk(group: click.Command, prefix: str) -> None:
        found[prefix] = group
        if isinstance(group, click.Group):
            for name, command in group.commands.items():
                walk(command, f"{prefix} {name}".strip())

    walk(cli, "")
    return found


def _synopses(page: Path) -> list[str]:
    """Inline ``stickslip ...`` spans; ``stickslip params list / show X / export Y`` gives one per subcommand."""
    spans = []
    for span in INLINE.findall(page.read_text(encoding="utf-8")):
        first, *others = span.replace("\\|", "|").split(" / ")
        spans.append(first)
        parent = " ".join(first.split()[:-1]) if len(first.split()) == 2 else " ".join(first.split()[:2])
        spans += [f"{parent} {other}" for other in others]
    return spans


def synopsis_problems(page: Path) -> list[str]:
    """Inline ``stickslip ...`` spans naming a command or an option that does not exist."""
    commands = _commands()
    problems = []
    for span in _synopses(page):
        words = span.split()[1:]
        path = ""
        while words and f"{path} {words[0]}".strip() in commands:
            path = f"{path} {words.pop(0)}".strip()
        command = commands[path]
        if isinstance(command, click.Group) and words and re.fullmatch(r"[a-z][a-z-]*", words[0]):
            problems.append(f"`{span}`: no command `stickslip {path} {words[0]}`".replace("  ", " "))
            continue
        known = {opt for param in command.params for opt in (*param.opts, *param.secondary_opts)} | {"--help", "-h"}
        for option in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*|-[a-zA-Z])\b", " ".join(words)):
            if option not in known:
                problems.append(f"`{span}`: `stickslip {path}` has no option {option}")
    return problems


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_inline_command_synopses_name_real_commands_and_options(page):
    problems = synopsis_problems(page)
    assert not problems, f"{_page_id(page)}:\n" + "\n".join(problems)


#: paths quoted from other projects, not files of this repository
FOREIGN_PATHS = {"tests/rsf_tests.py"}  # rsfmodel's test suite (docs/rsf.md)
DOTTED = re.compile(r"(?<![\w./-])(stickslip(?:\.[A-Za-z_]\w*)+)")
REPO_PATH = re.compile(r"(?<![\w/.-])((?:src|tests|benchmarks|scripts|docs)/[\w./*-]*\w)")
LINK = re.compile(r"\]\(([^)\s]+)\)")


def _resolve(dotted: str) -> object:
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            found = getattr(found, part)
        return found
    raise ImportError(dotted)


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_named_modules_functions_files_and_links_exist(page):
    text = page.read_text(encoding="utf-8")
    problems = []
    for dotted in sorted(set(DOTTED.findall(text))):
        try:
            _resolve(dotted)
        except (ImportError, AttributeError) as exc:
            problems.append(f"{dotted}: does not resolve ({type(exc).__name__}: {exc})")
    for path in sorted(set(REPO_PATH.findall(text)) - FOREIGN_PATHS):
        if not (any(ROOT.glob(path)) if "*" in path else (ROOT / path).exists()):
            problems.append(f"{path}: no such file in the repository")
    for target in sorted(set(LINK.findall(text))):
        if not re.match(r"[a-z]+:|#", target) and not (page.parent / target.split("#")[0]).exists():
            problems.append(f"link ({target}): no such file")
    assert not problems, f"{_page_id(page)}:\n" + "\n".join(problems)


def test_the_harness_sees_markers_failures_and_unknown_names(tmp_path, capsys):
    page = tmp_path / "page.md"
    page.write_text(
        "Text.\n\n<!-- test: replace 120 s -> 5 s -->\n```bash\nstickslip critical \\\n  --json  # note\n```\n"
        "\n    stickslip curve\n\n```\nuntagged\n```\n"
    )
    first, second = blocks(page)
    assert first.lang == "bash" and first.markers == [("replace", "120 s -> 5 s")] and second.lang == ""
    assert shell_lines(first.text, "bash") == ["stickslip critical    --json  # note"]
    assert len(indented_commands(page)) == 1
    with pytest.raises(AssertionError, match="does not occur"):
        first.runnable_text()
    with pytest.raises(AssertionError, match="exited 2"):
        run_shell_line('stickslip simulate --v0 50 --duration "1 s"', "here", capsys)
    with pytest.raises(AssertionError, match="shell operator"):
        run_shell_line("stickslip critical | head", "here", capsys)
    with pytest.raises(AttributeError):
        _resolve("stickslip.quasistatic.no_such_function")
    cycle = tmp_path / "cycle.md"
    cycle.write_text("Run `stickslip cycle --v0 V` or `stickslip rsf simulate --pull V`.\n")
    assert synopsis_problems(cycle) == [
        "`stickslip cycle --v0 V`: no command `stickslip cycle`",
        "`stickslip rsf simulate --pull V`: `stickslip rsf simulate` has no option --pull",
    ]


def test_shipped_third_party_data_keeps_its_licence_and_credit():
    """The sepiolite record is MIT-licensed by its author: the licence and the credit travel with the data."""
    folder = ROOT / "src" / "stickslip" / "data" / "giacomel-sepiolite"
    licence = (folder / "LICENSE").read_text()
    assert "MIT License" in licence and "Piercarlo Giacomel" in licence
    assert "pgiacomel/steadystate" in (folder / "README.md").read_text()
    assert (folder / "velstep3_TR2_exp013_sepiolite.txt").stat().st_size > 700_000  # the data, not an LFS pointer
    assert '"data/*/*"' in (ROOT / "pyproject.toml").read_text()  # package data: the wheel ships the folder


def test_expect_markers_check_python_prints_and_commands_never_print_nan(tmp_path, capsys):
    page = tmp_path / "page.md"
    page.write_text(
        "<!-- test: expect 42 -->\n```python\nprint(6 * 7)\n```\n\n"
        "<!-- test: expect 43 -->\n```python\nprint(6 * 7)\n```\n"
    )
    right, wrong = blocks(page)
    run_block(right, {}, capsys)
    with pytest.raises(AssertionError, match=r"quotes \['43'\]"):
        run_block(wrong, {}, capsys)
    assert quoted(
        "dc         64.1482 ± 11 µm   95 % [46.1729, 89.1213]",
        "x\ndc         64.1521 ± 11 µm   95 % [46.1752, 89.1277]\n",
    )
    assert not quoted("dc         64.1482 ± 11 µm", "dc         64.2482 ± 11 µm")  # 1.6e-3 off
    assert not quoted("dc         64.1482 ± 11 µm", "dc         64.1482 ± 12 µm")  # an integer differs
    assert not quoted("dc         64.1482 ± 11 µm", "dc 64.1482 ± 11 µm")  # the text between differs
    assert quoted("reduced chi-square 8.156 (noise 0.000365)", "reduced chi-square 8.155 (noise 0.000365), rms")
    assert NON_FINITE.search("period nan s") and NON_FINITE.search("Kc = -inf Pa/m") and NON_FINITE.search("NaN")
    assert not NON_FINITE.search("info: infinite stiffness, an inflection, nanometre")
    assert float_noise("mu0 0.00035999999999999997 and t = 10.000000000000002 s") == [
        "0.00035999999999999997",
        "10.000000000000002",
    ]
    assert float_noise("σ = 292.943 Pa, 1e-300, 100000 steps\n1.0,2.0000000000000004,3.0,4.0") == []
