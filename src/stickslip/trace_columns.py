"""Column names of the traces the package writes: one source for the writers and for ``analyze``.

Kept free of imports so that reading a trace never pulls in a model.
"""

from __future__ import annotations

#: The columns the run commands wrote before each became a spelling of ``run --model`` (which writes :data:`RUN`):
#: ``analyze`` still reads users' files of them.
#: ``simulate -o`` (quasi-static cycles; SI units: s, Pa, m/s, m, m, m, Nc/Nc0, phase name).
QUASI_STATIC = (
    "time",
    "stress",
    "velocity",
    "slider_displacement",
    "puller_displacement",
    "block_shear",
    "chain_fraction",
    "phase",
)
#: ``transient -o`` (the time-dependent bond model, Eqs 1-5).
TRANSIENT = ("time", "stress", "bonded_fraction", "slider_velocity", "slider_position", "puller_position")
#: ``transient --stick-population -o`` adds these: Nc/Nc0 where the chains hold, and what holds the block.
TRANSIENT_CHAINS = ("chain_fraction", "held_by")
#: ``rsf simulate -o`` (rate-and-state; a second state variable adds ``state2``).
RATE_AND_STATE = ("time", "friction", "slider_velocity", "state", "load_point_displacement", "slider_displacement")
#: ``Run.to_csv`` (any model through stickslip.models; ``run -o`` and its spellings ``simulate``, ``transient``,
#: ``rsf simulate``): these, then the model's own state columns.
RUN = ("time", "stress", "friction", "slider_velocity", "slider_position", "load_point_position")

#: Every column of the package's own traces beyond time and stress: ``analyze`` reads them as known, unused.
MODEL_COLUMNS = tuple(
    dict.fromkeys(
        c
        for c in (*QUASI_STATIC, *TRANSIENT, *TRANSIENT_CHAINS, *RATE_AND_STATE, *RUN, "state2")
        if c not in ("time", "stress")
    )
)
