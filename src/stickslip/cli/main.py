"""The ``stickslip`` command: a click group whose subcommands live one module per topic.

Errors a user can cause end as one line on stderr and exit status 2; no
traceback ever reaches the user.
"""

from __future__ import annotations

import sys

import click

from ..errors import StickslipError


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="stickslip")
def cli() -> None:
    """Friction and stick-slip of soft solids: the bond-population model of Juvekar & Singh."""


def _register() -> None:
    from . import analyze_cmd, cycle_cmd, fit_cmd, params_cmd, reproduce_cmd, steady_cmd, transient_cmd

    for module in (params_cmd, steady_cmd, cycle_cmd, fit_cmd, analyze_cmd, reproduce_cmd, transient_cmd):
        module.register(cli)


_register()


def main(argv: list[str] | None = None) -> None:
    """Console entry point."""
    try:
        cli.main(args=argv, prog_name="stickslip", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("stickslip: aborted", err=True)
        sys.exit(130)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.ClickException as exc:  # usage errors, bad option values, unwritable files
        message = exc.format_message().replace("\n", " ")
        click.echo(f"stickslip: error: {message}", err=True)
        sys.exit(2)
    except StickslipError as exc:
        click.echo(f"stickslip: error: {exc}".replace("\n", " "), err=True)
        sys.exit(2)
    except KeyboardInterrupt:
        sys.exit(130)
    except Exception as exc:  # a bug: still one line, but say it is ours
        click.echo(f"stickslip: internal error ({type(exc).__name__}): {exc}".replace("\n", " "), err=True)
        sys.exit(1)
    sys.exit(0)


if __name__ == "__main__":  # pragma: no cover
    main()
