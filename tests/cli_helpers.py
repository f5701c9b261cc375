"""Running the command line in-process, for the CLI tests."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from stickslip.cli.main import cli, main


def run(runner: CliRunner, *args: str) -> str:
    """A command that must succeed: its standard output."""
    result = runner.invoke(cli, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


def run_main(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    """``main()`` in-process, as the console script runs it: (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        main(list(args))
    out, err = capsys.readouterr()
    return int(exit_info.value.code), out, err


def run_main_bytes(capsysbinary: pytest.CaptureFixture[bytes], *args: str) -> tuple[int, bytes, str]:
    """``main()`` in-process with standard output as bytes (a PNG there must not break the capture)."""
    with pytest.raises(SystemExit) as exit_info:
        main(list(args))
    out, err = capsysbinary.readouterr()
    return int(exit_info.value.code), out, err.decode()


def ctrl_c_as_at_a_terminal() -> None:
    """``preexec_fn`` of a child that a test stops with SIGINT: the default disposition, as under a terminal.

    A test run started in the background by a shell without job control (``bash .ci/run &``) inherits SIGINT
    ignored, and Python then installs no KeyboardInterrupt handler in the child: a stopped sweep finished its points
    and exited 0 (the CI run of round 31)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)
