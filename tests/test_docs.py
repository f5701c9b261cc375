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
* ``<!-- test: before COMMAND -->``: a shell line run first, to make the block's input files.

Inline code that starts with ``stickslip`` (synopses in tables and prose) is checked too: its command must exist
and every ``--option`` in it must be one of that command's.
"""

from __future__ import annotations

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
SHOWN = {"text", "json", "toml", "csv"}
FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})\s*(?P<lang>[^\s`]*)")
MARKER = re.compile(r"^\s*<!--\s*test:\s*(?P<kind>skip|replace|before)\b\s*(?P<arg>.*?)\s*-->\s*$")
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
        return f"{self.page.relative_to(ROOT)}:{self.line}"

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
    return str(page.relative_to(ROOT))


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
            hits.append(f"{page.relative_to(ROOT)}:{number}: {line.strip()}")
        previous_blank = not line.strip()
    return hits


def shell_lines(text: str, lang: str) -> list[str]:
    """Logical command lines: continuations joined; for ``console`` only the ``$ `` lines."""
    joined = text.replace("\\\n", " ")
    lines = [line.strip() for line in joined.splitlines()]
    if lang == "console":
        return [line[2:] for line in lines if line.startswith("$ ")]
    return [line for line in lines if line and not line.startswith("#")]


def run_shell_line(line: str, where: str, capsys: pytest.CaptureFixture[str]) -> None:
    words = shlex.split(line, comments=True)
    unsupported = {"|", ">", ">>", "<", ";", "||", "&"} & set(words)
    assert not unsupported, f"{where}: cannot run {line!r} (shell operator {unsupported}); mark the block"
    command: list[str] = []
    for word in [*words, "&&"]:
        if word != "&&":
            command.append(word)
            continue
        if command:
            run_command(command, where, capsys)
        command = []


def run_command(argv: list[str], where: str, capsys: pytest.CaptureFixture[str]) -> None:
    program = Path(argv[0]).name
    if program == "stickslip":
        capsys.readouterr()
        with pytest.raises(SystemExit) as exit_info:
            main(argv[1:])
        out, err = capsys.readouterr()
        status = exit_info.value.code or 0
        assert status == 0, f"{where}: `{shlex.join(argv)}` exited {status}:\n{err[-2000:]}\n{out[-1000:]}"
    elif program in {"python", "python3"} and len(argv) == 3 and argv[1] == "-c":
        exec(compile(argv[2], where, "exec"), {"__name__": "__main__"})
    else:
        pytest.fail(f"{where}: no runner for `{shlex.join(argv)}`; mark the block (skip REASON) if it is not run")


def run_block(block: Block, namespace: dict, capsys: pytest.CaptureFixture[str]) -> None:
    for kind, arg in block.markers:
        if kind == "before":
            run_shell_line(arg, f"{block.where} (before)", capsys)
    text = block.runnable_text()
    if block.lang == "python":
        exec(compile(text, block.where, "exec"), namespace)
        capsys.readouterr()
    else:
        for line in shell_lines(text, block.lang):
            run_shell_line(line, block.where, capsys)


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_every_block_is_tagged_and_marked_with_reasons(page):
    for block in blocks(page):
        assert block.lang in RUNNABLE | SHOWN, (
            f"{block.where}: a fenced block must say what it is (```bash, ```python, ```text, ...), got {block.lang!r}"
        )
        reason = block.skip_reason()
        assert reason is None or len(reason) > 10, f"{block.where}: `test: skip` needs its reason"
        block.runnable_text()  # every replace marker applies
    assert not indented_commands(page), "commands in indented blocks are not tested; fence them:\n" + "\n".join(
        indented_commands(page)
    )


@pytest.mark.parametrize("page", [p for p in PAGES if any(b.lang in RUNNABLE for b in blocks(p))], ids=_page_id)
def test_documented_commands_and_examples_run(page, tmp_path, monkeypatch, capsys):
    runnable = [b for b in blocks(page) if b.lang in RUNNABLE]
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


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_inline_command_synopses_name_real_commands_and_options(page):
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
    assert not problems, f"{_page_id(page)}:\n" + "\n".join(problems)
