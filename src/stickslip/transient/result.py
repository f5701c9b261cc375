"""The result of a time-dependent run: the trace, its cycles, snapshots of the bond population."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import with_units
from ..quasistatic.cycle import Cycle
from ..reprs import compact_repr
from ..trace_columns import TRANSIENT

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

#: Trace columns, in order (SI units).
TRACE_COLUMNS = TRANSIENT


@dataclass(frozen=True)
class Snapshot:
    """The bond population at one instant: one entry per cohort (oldest first)."""

    time: float
    age: np.ndarray  # s
    extension: np.ndarray  # m, slider travel since the bond formed
    weight: np.ndarray  # bonds per m^2 in the cohort

    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        return with_units(pd.DataFrame({"age": self.age, "extension": self.extension, "weight": self.weight}))


@dataclass(frozen=True)
class Bookkeeping:
    """Running totals at each trace row (per m^2): bonds born and broken, puller work, dissipation, energies."""

    born: np.ndarray
    broken: np.ndarray
    work: np.ndarray  # J/m^2 done by the puller (velocity control: by the rig on the slider)
    dissipation: np.ndarray  # elastic energy of the chains lost when they broke
    bond_energy: np.ndarray  # FENE energy stored in the attached chains
    block_energy: np.ndarray  # sigma^2/(2K) (zero under velocity control)
    #: the integral of sigma dt from the start (Pa s), as the solver integrates it (mean stresses come from it)
    stress_integral: np.ndarray | None = None


@dataclass(frozen=True)
class TransientResult:
    """A run of the time-dependent population balance (Eqs 1-5); arrays in SI units."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    stress: np.ndarray
    bonded_fraction: np.ndarray
    slider_velocity: np.ndarray
    slider_position: np.ndarray
    puller_position: np.ndarray
    regime: str
    cycles: tuple[Cycle, ...]
    message: str
    control: str
    stiffness: float
    snapshots: tuple[Snapshot, ...] = field(default=(), repr=False)
    bookkeeping: Bookkeeping | None = field(default=None, repr=False)
    chain_fraction: np.ndarray | None = field(default=None, repr=False)  # Nc/Nc0 (stick population only)
    steps: int = 0
    rejected: int = 0
    #: the lowest stress of the solver's accepted states since the previous row (Pa): troughs from the solution
    lowest_stress: np.ndarray | None = field(default=None, repr=False)
    #: the highest stress of those states (Pa), the times of the lowest and the highest (s; the row's own unless a
    #: state between the rows went beyond it) and the fastest slider among them (m/s): a summary read from rows
    #: sampled by ``every`` takes its extremes from these, not from the rows kept
    highest_stress: np.ndarray | None = field(default=None, repr=False)
    lowest_time: np.ndarray | None = field(default=None, repr=False)
    highest_time: np.ndarray | None = field(default=None, repr=False)
    fastest_velocity: np.ndarray | None = field(default=None, repr=False)
    #: the block's mass (kg/m^2) and viscous damping (Pa s/m); 0: the paper's massless block
    mass: float = 0.0
    damping: float = 0.0
    #: the classifier's evidence for ``regime`` (periods seen, amplitude ratio, period, extremes; None if stopped)
    evidence: Any = field(default=None, repr=False)
    #: the massless block's jumps through rupture cascades (transient.jump.Jump: instant, stresses, travel)
    jumps: tuple[Any, ...] = field(default=(), repr=False)
    #: "ok"; "failed" where the model cannot continue before the protocol's end, "stopped" at a budget (the run up
    #: to there: ``BudgetExhausted.partial``); ``message`` says where
    status: str = "ok"
    #: Vc of Eq 9 (m/s), the aging steady curve's minimum for the run's parameters; NaN without aging or a minimum
    critical_velocity: float = float("nan")

    @property
    def final_stress(self) -> float:
        return float(self.stress[-1])

    @property
    def final_bonded_fraction(self) -> float:
        return float(self.bonded_fraction[-1])

    def summary(self) -> dict[str, Any]:
        """The JSON summary (SI units)."""
        return {
            "regime": self.regime,
            "final_stress": self.final_stress,
            "final_bonded_fraction": self.final_bonded_fraction,
            "final_velocity": float(self.slider_velocity[-1]),
            "end_time": float(self.time[-1]),
            "control": self.control,
            "stiffness": self.stiffness,
            "steps": self.steps,
            "cycles": [c.as_dict() for c in self.cycles],
            "message": self.message,
            "status": self.status,
        } | ({"jumps": [asdict(j) for j in self.jumps]} if self.jumps else {})

    @property
    def held_by(self) -> np.ndarray:
        """What holds the block at each row: ``"bonds"`` (Eq 1's population) or ``"chains"`` (the paper's stick
        chains, which take the load while the slider is stuck; Eq 1's bonds are set aside then, and
        ``bonded_fraction`` reads 0)."""
        if self.chain_fraction is None:
            return np.full(self.time.size, "bonds", dtype=object)
        return np.where(np.isfinite(self.chain_fraction), "chains", "bonds").astype(object)

    def to_frame(self) -> pd.DataFrame:
        """The trace: columns :data:`TRACE_COLUMNS`, SI units; with the stick chains also ``chain_fraction``
        (Nc/Nc0, empty where they do not hold) and ``held_by`` (bonds or chains)."""
        import pandas as pd

        columns = {name: getattr(self, name) for name in TRACE_COLUMNS}
        if self.chain_fraction is not None:
            columns["chain_fraction"] = self.chain_fraction
            columns["held_by"] = self.held_by
        return with_units(pd.DataFrame(columns))

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Stress against time (and the slider velocity on a twin axis); returns the Axes."""
        from ..plots.transient import plot_transient

        return plot_transient(self, ax=ax, **kwargs)
