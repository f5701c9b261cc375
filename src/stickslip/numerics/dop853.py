"""scipy's DOP853 steps in scalar Python, for the stick phase's field (g(y), g(y) - 1) in the variable theta.

:func:`stickslip.quasistatic.stick.stick_phase` integrates Eq 15 in an arc-length-like variable theta, where the
field is (dt'/dtheta, dn/dtheta) = (g, g - 1) with g = 1/(1 + w) (docs/stick-phase.md §3).  Through
:func:`scipy.integrate.solve_ivp` each of its ~60 steps cost ~140 us, almost all of it NumPy's overhead on arrays
of two numbers (issue 31).  This module takes the same steps on Python floats: the same Dormand-Prince 8(5,3)
tableau, initial step (Hairer et al. II.4), step-size control, event location (brentq on the 7th-order dense
output, xtol = rtol = 4 eps) and dense output as scipy 1.17's ``DOP853`` and ``solve_ivp``, so its answers are
scipy's up to rounding (the tests compare the two).  Two things are specific to this field, both exact:

* the field is a function of the state alone, and its second component is the first minus 1, so a stage costs
  one call of g and one weighted sum: the n-component's is the t'-component's minus the sum of the coefficients
  (exact up to rounding of the order of eps h).  The error estimate and the dense output are formed from g - 1
  as scipy forms them: there that cancellation would matter, as the weights sum to 0;
* the dense output's extra stages and coefficients are formed only for the steps that are evaluated (scipy forms
  them after every step when dense output is asked for).

The coefficients are those of scipy's ``scipy/integrate/_ivp/dop853_coefficients.py`` (BSD-3-Clause), from
Hairer's Fortran DOP853; copied so that the stick solver does not load scipy.integrate.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from operator import mul

import numpy as np

from ..errors import ModelError
from .roots import brentq  # scipy's Brent bit for bit (tests/test_roots.py), without scipy.optimize

_C = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
]

_A = [[0.0] * 16 for _ in range(16)]
_A[1][0] = 5.26001519587677318785587544488e-2
_A[2][0] = 1.97250569845378994544595329183e-2
_A[2][1] = 5.91751709536136983633785987549e-2
_A[3][0] = 2.95875854768068491816892993775e-2
_A[3][2] = 8.87627564304205475450678981324e-2
_A[4][0] = 2.41365134159266685502369798665e-1
_A[4][2] = -8.84549479328286085344864962717e-1
_A[4][3] = 9.24834003261792003115737966543e-1
_A[5][0] = 3.7037037037037037037037037037e-2
_A[5][3] = 1.70828608729473871279604482173e-1
_A[5][4] = 1.25467687566822425016691814123e-1
_A[6][0] = 3.7109375e-2
_A[6][3] = 1.70252211019544039314978060272e-1
_A[6][4] = 6.02165389804559606850219397283e-2
_A[6][5] = -1.7578125e-2
_A[7][0] = 3.70920001185047927108779319836e-2
_A[7][3] = 1.70383925712239993810214054705e-1
_A[7][4] = 1.07262030446373284651809199168e-1
_A[7][5] = -1.53194377486244017527936158236e-2
_A[7][6] = 8.27378916381402288758473766002e-3
_A[8][0] = 6.24110958716075717114429577812e-1
_A[8][3] = -3.36089262944694129406857109825
_A[8][4] = -8.68219346841726006818189891453e-1
_A[8][5] = 2.75920996994467083049415600797e1
_A[8][6] = 2.01540675504778934086186788979e1
_A[8][7] = -4.34898841810699588477366255144e1
_A[9][0] = 4.77662536438264365890433908527e-1
_A[9][3] = -2.48811461997166764192642586468
_A[9][4] = -5.90290826836842996371446475743e-1
_A[9][5] = 2.12300514481811942347288949897e1
_A[9][6] = 1.52792336328824235832596922938e1
_A[9][7] = -3.32882109689848629194453265587e1
_A[9][8] = -2.03312017085086261358222928593e-2
_A[10][0] = -9.3714243008598732571704021658e-1
_A[10][3] = 5.18637242884406370830023853209
_A[10][4] = 1.09143734899672957818500254654
_A[10][5] = -8.14978701074692612513997267357
_A[10][6] = -1.85200656599969598641566180701e1
_A[10][7] = 2.27394870993505042818970056734e1
_A[10][8] = 2.49360555267965238987089396762
_A[10][9] = -3.0467644718982195003823669022
_A[11][0] = 2.27331014751653820792359768449
_A[11][3] = -1.05344954667372501984066689879e1
_A[11][4] = -2.00087205822486249909675718444
_A[11][5] = -1.79589318631187989172765950534e1
_A[11][6] = 2.79488845294199600508499808837e1
_A[11][7] = -2.85899827713502369474065508674
_A[11][8] = -8.87285693353062954433549289258
_A[11][9] = 1.23605671757943030647266201528e1
_A[11][10] = 6.43392746015763530355970484046e-1
_A[12][0] = 5.42937341165687622380535766363e-2
_A[12][5] = 4.45031289275240888144113950566
_A[12][6] = 1.89151789931450038304281599044
_A[12][7] = -5.8012039600105847814672114227
_A[12][8] = 3.1116436695781989440891606237e-1
_A[12][9] = -1.52160949662516078556178806805e-1
_A[12][10] = 2.01365400804030348374776537501e-1
_A[12][11] = 4.47106157277725905176885569043e-2
_A[13][0] = 5.61675022830479523392909219681e-2
_A[13][6] = 2.53500210216624811088794765333e-1
_A[13][7] = -2.46239037470802489917441475441e-1
_A[13][8] = -1.24191423263816360469010140626e-1
_A[13][9] = 1.5329179827876569731206322685e-1
_A[13][10] = 8.20105229563468988491666602057e-3
_A[13][11] = 7.56789766054569976138603589584e-3
_A[13][12] = -8.298e-3
_A[14][0] = 3.18346481635021405060768473261e-2
_A[14][5] = 2.83009096723667755288322961402e-2
_A[14][6] = 5.35419883074385676223797384372e-2
_A[14][7] = -5.49237485713909884646569340306e-2
_A[14][10] = -1.08347328697249322858509316994e-4
_A[14][11] = 3.82571090835658412954920192323e-4
_A[14][12] = -3.40465008687404560802977114492e-4
_A[14][13] = 1.41312443674632500278074618366e-1
_A[15][0] = -4.28896301583791923408573538692e-1
_A[15][5] = -4.69762141536116384314449447206
_A[15][6] = 7.68342119606259904184240953878
_A[15][7] = 4.06898981839711007970213554331
_A[15][8] = 3.56727187455281109270669543021e-1
_A[15][12] = -1.39902416515901462129418009734e-3
_A[15][13] = 2.9475147891527723389556272149
_A[15][14] = -9.15095847217987001081870187138

_B = _A[12][:12]
_E3 = [*_B, 0.0]
_E3[0] -= 0.244094488188976377952755905512
_E3[8] -= 0.733846688281611857341361741547
_E3[11] -= 0.220588235294117647058823529412e-1
_E5 = [0.0] * 13
_E5[0] = 0.1312004499419488073250102996e-1
_E5[5] = -0.1225156446376204440720569753e1
_E5[6] = -0.4957589496572501915214079952
_E5[7] = 0.1664377182454986536961530415e1
_E5[8] = -0.3503288487499736816886487290
_E5[9] = 0.3341791187130174790297318841
_E5[10] = 0.8192320648511571246570742613e-1
_E5[11] = -0.2235530786388629525884427845e-1
_D = [[0.0] * 16 for _ in range(4)]
for _row, _entries in enumerate(
    (
        (-0.84289382761090128651353491142e1, 0.56671495351937776962531783590, -0.30689499459498916912797304727e1,
         0.23846676565120698287728149680e1, 0.21170345824450282767155149946e1, -0.87139158377797299206789907490,
         0.22404374302607882758541771650e1, 0.63157877876946881815570249290, -0.88990336451333310820698117400e-1,
         0.18148505520854727256656404962e2, -0.91946323924783554000451984436e1, -0.44360363875948939664310572000e1),
        (0.10427508642579134603413151009e2, 0.24228349177525818288430175319e3, 0.16520045171727028198505394887e3,
         -0.37454675472269020279518312152e3, -0.22113666853125306036270938578e2, 0.77334326684722638389603898808e1,
         -0.30674084731089398182061213626e2, -0.93321305264302278729567221706e1, 0.15697238121770843886131091075e2,
         -0.31139403219565177677282850411e2, -0.93529243588444783865713862664e1, 0.35816841486394083752465898540e2),
        (0.19985053242002433820987653617e2, -0.38703730874935176555105901742e3, -0.18917813819516756882830838328e3,
         0.52780815920542364900561016686e3, -0.11573902539959630126141871134e2, 0.68812326946963000169666922661e1,
         -0.10006050966910838403183860980e1, 0.77771377980534432092869265740, -0.27782057523535084065932004339e1,
         -0.60196695231264120758267380846e2, 0.84320405506677161018159903784e2, 0.11992291136182789328035130030e2),
        (-0.25693933462703749003312586129e2, -0.15418974869023643374053993627e3, -0.23152937917604549567536039109e3,
         0.35763911791061412378285349910e3, 0.93405324183624310003907691704e2, -0.37458323136451633156875139351e2,
         0.10409964950896230045147246184e3, 0.29840293426660503123344363579e2, -0.43533456590011143754432175058e2,
         0.96324553959188282948394950600e2, -0.39177261675615439165231486172e2, -0.14972683625798562581422125276e3),
    )
):  # fmt: skip
    for _col, _value in zip((0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), _entries, strict=True):
        _D[_row][_col] = _value

#: rows of the tableau cut to the stages they use (a stage's own and later coefficients are 0)
_ROWS = [_A[s][:s] for s in range(16)]
#: their sums (c of the stages), for the n-components of the stages: sum(a_j (g_j - 1)) = sum(a_j g_j) - sum(a_j)
_ROW_SUMS = [math.fsum(row) for row in _ROWS]
_B_SUM = math.fsum(_B)
_EPS = float(np.finfo(float).eps)
#: scipy's step-size control of explicit Runge-Kutta pairs
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_ERROR_EXPONENT = -1.0 / 8.0  # the error estimator is of order 7


class Steps:
    """The dense output of the steps taken: (t', n) at theta, like scipy's OdeSolution.

    Called with a float it returns a tuple (t', n); with an array of m values, an array of shape (2, m).
    """

    def __init__(self, hold: Callable[[float, float], float]) -> None:
        self.hold = hold
        self.starts: list[float] = []  # theta at the start of each step
        self.widths: list[float] = []
        self.states: list[tuple[float, float, float, float]] = []  # (t', n) at the start and the end
        self.stages: list[list[float]] = []  # g at the 13 stages (the last: at the end of the step)
        self.coefficients: list[tuple[list[float], list[float]] | None] = []
        self.end = 0.0

    @property
    def start(self) -> float:
        return self.starts[0]

    def add(self, start: float, width: float, state: tuple[float, float, float, float], stages: list[float]) -> None:
        self.starts.append(start)
        self.widths.append(width)
        self.states.append(state)
        self.stages.append(stages)
        self.coefficients.append(None)
        self.end = start + width

    def _coefficients(self, i: int) -> tuple[list[float], list[float]]:
        """The 7 interpolation coefficients of step ``i`` for t' and n (scipy's Dop853DenseOutput.F)."""
        if self.coefficients[i] is None:
            self._fill_coefficients([i])
        found = self.coefficients[i]
        assert found is not None
        return found

    def _fill_coefficients(self, indices: list[int]) -> None:
        """The interpolation coefficients (:meth:`_coefficients`) of many steps at once: the sums as matrix products
        over the steps (the stick phase's 400-point trace asked for ~45 steps' one by one, each sum in Python: half
        of a stick phase's time).  The extra stages' field values are taken one by one."""
        if not indices:
            return
        h = np.array([self.widths[i] for i in indices])
        states = np.array([self.states[i] for i in indices])
        tp, n = states[:, 0], states[:, 1]
        k = np.array([self.stages[i] for i in indices])  # (m, 13)
        k_n = k - 1.0
        hold = self.hold
        for row in _ROWS[13:]:
            weights = np.array(row)
            at_tp = tp + (k @ weights) * h
            at_n = n + (k_n @ weights) * h
            g = np.array([hold(a, b) for a, b in zip(at_tp.tolist(), at_n.tolist(), strict=True)])
            k = np.column_stack([k, g])
            k_n = np.column_stack([k_n, g - 1.0])
        d = np.array(_D)  # (4, 16)
        d_tp, d_n = states[:, 2] - tp, states[:, 3] - n
        f_tp = np.column_stack([d_tp, h * k[:, 0] - d_tp, 2 * d_tp - h * (k[:, 12] + k[:, 0]), h[:, None] * (k @ d.T)])
        f_n = np.column_stack(
            [d_n, h * k_n[:, 0] - d_n, 2 * d_n - h * (k_n[:, 12] + k_n[:, 0]), h[:, None] * (k_n @ d.T)]
        )
        for j, i in enumerate(indices):
            self.coefficients[i] = (f_tp[j].tolist(), f_n[j].tolist())

    def _index(self, theta: float) -> int:
        # the step holding theta (the earlier one at a break point, as scipy's OdeSolution)
        lo, hi = 0, len(self.starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.starts[mid] < theta:
                lo = mid
            else:
                hi = mid - 1
        return lo

    def at(self, theta: float) -> tuple[float, float]:
        """(t', n) at ``theta`` (clipped to the range integrated)."""
        theta = min(max(theta, self.starts[0]), self.end)
        i = self._index(theta)
        f_tp, f_n = self._coefficients(i)
        x = (theta - self.starts[i]) / self.widths[i]
        y_tp = y_n = 0.0
        for j in range(6, -1, -1):  # scipy's nested product: alternately times x and times 1 - x
            y_tp += f_tp[j]
            y_n += f_n[j]
            factor = x if j % 2 == 0 else 1.0 - x
            y_tp *= factor
            y_n *= factor
        state = self.states[i]
        return y_tp + state[0], y_n + state[1]

    def __call__(self, theta: float | np.ndarray) -> tuple[float, float] | np.ndarray:
        if np.ndim(theta) == 0:
            return self.at(float(theta))
        values = np.clip(np.asarray(theta, dtype=float), self.starts[0], self.end)
        starts = np.asarray(self.starts)
        which = np.clip(np.searchsorted(starts, values, side="left") - 1, 0, len(self.starts) - 1)
        used = np.unique(which)
        self._fill_coefficients([i for i in used.tolist() if self.coefficients[i] is None])
        table = np.zeros((len(self.starts), 2, 7))
        origin = np.zeros((len(self.starts), 2))
        for i in used.tolist():
            table[i] = self._coefficients(i)
            origin[i] = self.states[i][:2]
        x = (values - starts[which]) / np.asarray(self.widths)[which]
        coefficients = table[which]  # (m, 2, 7)
        y = np.zeros((values.size, 2))
        for j in range(6, -1, -1):
            y += coefficients[:, :, j]
            y *= (x if j % 2 == 0 else 1.0 - x)[:, None]
        y += origin[which]
        return y.T


@dataclass(frozen=True)
class Outcome:
    """How :func:`integrate` stopped: at the terminal event n = 0, a positive decision, or the last checkpoint."""

    steps: Steps
    s_end: float
    y_end: tuple[float, float]
    reason: str  # "event", "decided" or "horizon"


def _initial_step(hold: Callable[[float, float], float], tp: float, n: float, g: float, length: float, rtol: float,
                  atol: float) -> float:  # fmt: skip
    """scipy's select_initial_step (Hairer et al. II.4) for an error estimator of order 7."""
    if length == 0.0:
        return 0.0
    sc_tp, sc_n = atol + abs(tp) * rtol, atol + abs(n) * rtol
    d0 = math.sqrt(0.5 * ((tp / sc_tp) ** 2 + (n / sc_n) ** 2))
    d1 = math.sqrt(0.5 * ((g / sc_tp) ** 2 + ((g - 1.0) / sc_n) ** 2))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, length)
    g1 = hold(tp + h0 * g, n + h0 * (g - 1.0))
    d2 = math.sqrt(0.5 * (((g1 - g) / sc_tp) ** 2 + (((g1 - 1.0) - (g - 1.0)) / sc_n) ** 2)) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100 * h0, h1, length)


def _chunk(hold: Callable[[float, float], float], s0: float, tp: float, n: float, s1: float, rtol: float,
           atol: float, steps: Steps) -> tuple[bool, float, float, float]:  # fmt: skip
    """solve_ivp(DOP853) from (s0, (t', n)) to s1 with the terminal event n = 0 (direction -1).

    Returns (whether the event stopped it, s, t', n at the stop).
    """
    g = hold(tp, n)  # every stage is (g, g - 1): g alone is kept
    h_abs = _initial_step(hold, tp, n, g, s1 - s0, rtol, atol)
    rows = list(zip(_ROWS[1:12], _ROW_SUMS[1:12], strict=True))
    s = s0
    while s != s1:  # solve_ivp's loop: a step, then the event
        min_step = 10 * abs(math.nextafter(s, math.inf) - s)
        if h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                raise ModelError(
                    f"integration failed at s = {s0:.6g}: Required step size is less than spacing between numbers."
                )
            s_new = s + h_abs
            if s_new > s1:
                s_new = s1
            h = s_new - s
            h_abs = abs(h)
            k = [g]
            for row, row_sum in rows:
                acc = sum(map(mul, k, row))
                k.append(hold(tp + acc * h, n + (acc - row_sum) * h))
            acc = sum(map(mul, k, _B))
            tp_new = tp + h * acc
            n_new = n + h * (acc - _B_SUM)
            g_new = hold(tp_new, n_new)
            k.append(g_new)
            k_n = [g_s - 1.0 for g_s in k]
            sc_tp = atol + max(abs(tp), abs(tp_new)) * rtol
            sc_n = atol + max(abs(n), abs(n_new)) * rtol
            e5_2 = (sum(map(mul, k, _E5)) / sc_tp) ** 2 + (sum(map(mul, k_n, _E5)) / sc_n) ** 2
            e3_2 = (sum(map(mul, k, _E3)) / sc_tp) ** 2 + (sum(map(mul, k_n, _E3)) / sc_n) ** 2
            if e5_2 == 0.0 and e3_2 == 0.0:
                error = 0.0
            else:
                error = h_abs * e5_2 / math.sqrt((e5_2 + 0.01 * e3_2) * 2)
            if error < 1.0:
                factor = _MAX_FACTOR if error == 0.0 else min(_MAX_FACTOR, _SAFETY * error**_ERROR_EXPONENT)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            h_abs *= max(_MIN_FACTOR, _SAFETY * error**_ERROR_EXPONENT)
            rejected = True
        steps.add(s, h, (tp, n, tp_new, n_new), k)
        if n >= 0.0 and n_new <= 0.0:  # the collapse, located on the dense output as solve_ivp does
            root = brentq(lambda theta: steps.at(theta)[1], s, s_new, xtol=4 * _EPS, rtol=4 * _EPS)
            steps.end = root
            tp_end, n_end = steps.at(root)
            return True, root, tp_end, n_end
        s, tp, n, g = s_new, tp_new, n_new, g_new
    return False, s, tp, n


def integrate(
    hold: Callable[[float, float], float],
    y0: tuple[float, float],
    checkpoints: Sequence[float],
    decide: Callable[[float, float, float], bool],
    rtol: float,
    atol: float,
    start: float = 0.0,
    steps: Steps | None = None,
) -> Outcome:
    """Integrate (t', n)' = (g, g - 1), g = ``hold(t', n)``, from ``start`` until n = 0, a decision or the last
    checkpoint (what :func:`stickslip.numerics.events.integrate_in_chunks` does with solve_ivp's DOP853).

    At each checkpoint ``decide(theta, t', n)`` is asked whether to stop; pass ``steps`` to extend earlier ones.
    """
    steps = Steps(hold) if steps is None else steps
    s, (tp, n) = float(start), (float(y0[0]), float(y0[1]))
    for s1 in checkpoints:
        if s1 <= s:
            continue
        collapsed, s, tp, n = _chunk(hold, s, tp, n, float(s1), rtol, atol, steps)
        if collapsed:
            return Outcome(steps, s, (tp, n), "event")
        if decide(s, tp, n):
            return Outcome(steps, s, (tp, n), "decided")
    return Outcome(steps, s, (tp, n), "horizon")
