"""The protocol vocabulary shared by every model's run command: what the rig does, in the same words everywhere.

``--v0 V --duration T``
    a first segment at constant velocity (the load point's through a spring, the slider's under velocity control);
``--segment "V:T"``
    further segments, repeatable (alone, they are the whole protocol, as ``rsf simulate`` always took them);
``--protocol FILE``
    the protocol as a CSV file (docs/protocols.md), instead of the three above;
``--stiffness K``
    the spring between the load point and the slider (each model reads it in its own unit: Pa/m for the bond
    models, friction per slip for rate-and-state);
``--control spring|velocity``
    the protocol drives the load point through the spring, or the slider itself (a rigid rig).
    ``block`` is the older name of ``spring`` and keeps working.

A model that cannot run what was asked (the quasi-static model is a spring at one constant velocity) refuses it
in one line naming the option, before anything is computed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click

from ..errors import ParameterError, UnitError
from .common import FILE_PATH, positive, require_unit, stacked

#: Rigs every run command names the same way.
CONTROLS = ("spring", "velocity")
#: Older spellings still accepted: ``transient --control block`` is the spring.
CONTROL_ALIASES = {"block": "spring"}


def protocol_options(
    stiffness_help: str = 'Spring stiffness K between the load point and the slider, e.g. "400 kPa/m".',
    control_default: str = "spring",
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Add ``--v0 --duration --segment --protocol --stiffness --control`` (parameters ``v0_text``,
    ``duration_text``, ``segment_texts``, ``protocol_file``, ``stiffness_text``, ``control``)."""

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        options = [
            click.option("--v0", "v0_text", metavar="V",
                         help='Velocity of the (first) segment, with its unit, e.g. "50 um/s" (>= 0).'),
            click.option("--duration", "duration_text", metavar="T",
                         help='Length of the (first) segment, e.g. "120 s".'),
            click.option("--segment", "segment_texts", multiple=True, metavar='"V:T"',
                         help='A (further) segment: velocity and duration, e.g. "1 mm/s:2 s"; repeatable.'),
            click.option("--protocol", "protocol_file", type=FILE_PATH,
                         help="The protocol as CSV (time,velocity or velocity,duration; docs/protocols.md)."),
            click.option("--stiffness", "stiffness_text", metavar="K", default=None, help=stiffness_help),
            click.option("--control", type=click.Choice([*CONTROLS, *CONTROL_ALIASES]), default=control_default,
                         show_default=True,
                         help="spring: the protocol moves the load point, a spring drives the slider (block is"
                         " the older name); velocity: it moves the slider itself (a rigid rig)."),
        ]  # fmt: skip
        return stacked(options, func)

    return decorate


def control_name(control: str) -> str:
    """The rig in the vocabulary's words: ``spring`` or ``velocity`` (``block`` is the spring)."""
    return CONTROL_ALIASES.get(control, control)


def build_protocol(
    v0_text: str | None,
    duration_text: str | None,
    segment_texts: Sequence[str],
    protocol_file: Path | None,
    fallback: Any = None,
) -> Any:
    """The :class:`stickslip.protocols.Protocol` the options describe (``fallback`` when they describe none)."""
    from ..protocols import Protocol, Segment, parse_segment, read_protocol

    if protocol_file is not None:
        if segment_texts or v0_text is not None or duration_text is not None:
            raise ParameterError("--protocol: give either a protocol file or --v0/--duration/--segment, not both")
        return read_protocol(protocol_file)
    if (v0_text is None) != (duration_text is None):
        given, missing = ("--v0", "--duration") if duration_text is None else ("--duration", "--v0")
        raise ParameterError(f"{given} needs {missing}: the first segment is a velocity and a length of time")
    segments = [parse_segment(checked_segment_text(text)) for text in segment_texts]
    if v0_text is not None and duration_text is not None:
        first = Segment(
            positive(v0_text, "velocity", "--v0", allow_zero=True), positive(duration_text, "time", "--duration")
        )
        segments.insert(0, first)
    if segments:
        return Protocol(tuple(segments))
    if fallback is not None:
        return fallback
    raise ParameterError('give the protocol: --v0 V --duration T, --segment "V:T" (repeatable) or --protocol FILE')


def checked_segment_text(text: str, name: str = "--segment") -> str:
    """``--segment "V:T"`` as typed, each of V and T with its unit (the API reads bare numbers as SI; a user who
    types ``50:60`` does not mean 50 m/s); zero needs none.  Returned unchanged for :func:`parse_segment`."""
    from ..protocols import split_segment
    from ..units import bare_number

    velocity_text, sep, duration_text = split_segment(text, name, f"{name} '1 mm/s:2 s'")
    for part, what in ((velocity_text, "velocity"), (duration_text, "duration")):
        number = bare_number(part) if sep else None
        if number is not None and number != 0:
            example = "1 mm/s:2 s"
            raise UnitError(
                f"{name} {text!r}: the {what} {part.strip()} needs a unit, e.g. {name} {example!r}"
                " (bare numbers are refused on the command line)"
            )
    return text


def refuse_unsupported(
    command: str,
    protocol: Any,
    control: str,
    *,
    controls: Sequence[str] = CONTROLS,
    one_segment: bool = False,
    instead: str = "",
) -> None:
    """Refuse, in one line naming the option, a rig or protocol the model of ``command`` cannot run."""
    control = control_name(control)
    hint = f" ({instead})" if instead else ""
    if control not in controls:
        can = " or ".join(f"--control {c}" for c in controls)
        raise ParameterError(f"--control {control}: {command} runs only with {can}{hint}")
    if one_segment and len(protocol.segments) > 1:
        raise ParameterError(
            f"--segment/--protocol: {command} runs at one constant velocity, not a protocol of"
            f" {len(protocol.segments)} segments{hint}"
        )


def inertia_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """``--mass`` and ``--damping``: the block's inertia and viscous damping (a spring rig's; build_rig reads them)."""
    options = [
        click.option("--mass", "mass_text", default=None, metavar="M",
                     help='Block mass per area, e.g. "10.5 kg/m^2" [none: the paper\'s massless block].'),
        click.option("--damping", "damping_text", default=None, metavar="ETA",
                     help='Viscous (radiation) damping of the block, e.g. "1025 Pa s/m" (needs --mass).'),
    ]  # fmt: skip
    return stacked(options, func)


def build_rig(
    control: str,
    stiffness_text: str | None,
    models: Sequence[Any] = (),
    mass_text: str | None = None,
    damping_text: str | None = None,
) -> tuple[Any, dict[str, str]]:
    """The :class:`stickslip.models.Rig` of ``--control``, ``--stiffness`` (K in Pa/m), ``--mass`` (kg/m^2) and
    ``--damping`` (Pa s/m), the one rig builder.

    Models whose own spring key ``k`` is in another unit (rate-and-state: friction per slip) also take
    ``--stiffness`` in that unit ("1e-3 1/um") when every model of ``models`` has such a key: it then sets ``k``
    in each, as ``--set k=...`` would.  Returns the rig and those settings, {model name: stiffness text}.
    """
    from ..models import Rig

    control = control_name(control)
    inertia = _inertia(control, mass_text, damping_text)
    if stiffness_text is None:
        return Rig(control=control, **inertia), {}
    if control == "velocity":
        raise ParameterError(
            "--stiffness: under --control velocity the rig is rigid and has no spring; drop --stiffness"
            " or use --control spring"
        )
    require_unit(stiffness_text, "stress_per_length", "--stiffness ")
    try:
        stiffness = positive(stiffness_text, "stress_per_length", "--stiffness")
        return Rig(control=control, stiffness=stiffness, **inertia), {}
    except UnitError:
        own = [m.dimensions().get("k") for m in models]
        if not own or None in own:
            raise
    for dimension in own:
        positive(stiffness_text, dimension, "--stiffness")  # the one-line error in the model's unit
    return Rig(control=control, **inertia), {m.name: stiffness_text for m in models}


def _inertia(control: str, mass_text: str | None, damping_text: str | None) -> dict[str, float]:
    """{mass, damping} of --mass and --damping (SI), refused in one line under --control velocity."""
    given = {"mass": mass_text, "damping": damping_text}
    if control == "velocity" and any(v is not None for v in given.values()):
        name = "--mass" if mass_text is not None else "--damping"
        raise ParameterError(
            f"{name}: under --control velocity the rig is rigid and has no block; use --control spring"
        )
    dimensions = {"mass": "mass_per_area", "damping": "stress_per_velocity"}
    return {
        key: positive(text, dimensions[key], f"--{key}", allow_zero=True)
        for key, text in given.items()
        if text is not None
    }
