"""Modal parameter identification from measured FRFs (Appendix A of the seed paper: "conventional modal parameter
identification" of the four lowest bending modes, Table A.1): the poly-reference least-squares complex frequency-domain
estimator (LSCF, Guillaume et al. 2003; Peeters et al. 2004 "PolyMAX" in its single-reference form) with a
stabilization diagram, an automatic choice of the stable poles, and the least-squares frequency-domain estimate (LSFD)
of the modal constants.

LSCF (one input, several outputs o, common denominator):

* The band [f_lo, f_hi] is mapped onto the unit circle with complex coefficients: z_k = exp(i (omega_k - omega_c) T),
  omega_c the band's centre and T = BAND_FILL * pi / (half the band's width in rad/s), so the band fills most of the
  circle (good conditioning) and each mode in the band is one complex pole (its conjugate lies outside the band).
* Model H_o(omega_k) = B_o(z_k) / A(z_k), polynomials of order n; the linearised error w_k (B_o - H_o A) in least
  squares. Eliminating the numerators gives the reduced normal equations M alpha = 0 with
  M = sum_o (T_o - S_o^H R_o^-1 S_o), R_o, S_o, T_o Toeplitz in z^(j-i) (sums over the lines, computed once for the
  highest order; an order n uses their leading blocks), solved with the highest coefficient 1.
* The weights w_k = 1 / |H_o(omega_k)| fit every mode relative to its own level (the displacement FRF spans five
  decades from mode 1 to mode 4), like a fit of log H.
* Poles lambda = ln(z) / T + i omega_c (rad/s); kept when their damped frequency lies in the band and they decay.

Sub-bands: a band wider than a factor SEGMENT_SPAN^2 is fitted in overlapping sub-bands (centres SEGMENT_STEP apart
on a log scale, each reaching a factor SEGMENT_SPAN to either side), and each keeps the poles of its middle part (a
factor sqrt(SEGMENT_STEP) to either side): one polynomial across five decades of FRF level and a hundred-fold band
would need a high order and still miss the low, sharp mode 1 of Table A.1, while each sub-band needs a low order and
sees a mode away from its edges.

Stabilization and choice of poles: a pole of order n is stable in frequency when the nearest pole of order n - 1 lies
within STABLE_FREQUENCY (relative), stable when its damping ratio also agrees within STABLE_DAMPING. Stable poles of all
orders are grouped by frequency (gaps below CLUSTER_GAP); a group seen at MIN_SHARE of the orders (at least 3) is a
physical mode, whose frequency and damping are the medians over the group's poles of the upper half of its orders.
With `modes` given, the modes with the highest peaks of the synthesized accelerance (|A_o| / (2 D), summed over the
outputs) are kept: the accelerometer's view, in which a weak mode of the clamping near mode 2 stays below mode 4,
whereas in the displacement FRF (peaks |A| / (2 D omega^2)) it may not.

LSFD: the real-mode form H_o(omega) = sum_j A_oj / (omega_j^2 - omega^2 + 2 i D_j omega_j omega) - LR_o / omega^2 + UR_o
with complex unknowns A_oj (the modal constants, 1/kg for displacement per force; for a driving point A_j = phi_j^2 of
the mass-normalised mode), a lower residual LR_o (modes below the band) and an upper residual UR_o (modes above it),
weighted like LSCF. The modal constants reported are the real parts (their complexity, |Im A| / |A|, goes with them).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from sim.common.errors import SimulationInputError

#: share of the unit circle the band fills on each side of its centre
BAND_FILL = 0.9
#: stable in frequency: the nearest pole of the order below within this relative distance
STABLE_FREQUENCY = 2e-3
#: stable: and its damping ratio within this relative distance
STABLE_DAMPING = 0.05
#: stable poles closer than this (relative frequency) are one group
CLUSTER_GAP = 2e-3
#: a group seen at this share of the orders is a physical mode
MIN_SHARE = 0.25
#: default highest order of the stabilization diagram (of each sub-band)
MAX_ORDER = 20
#: sub-bands: centres this factor apart, each reaching this factor to either side of its centre
SEGMENT_STEP = 1.2
SEGMENT_SPAN = 1.25


@dataclass(frozen=True)
class Band:
    """A frequency band lo..hi (Hz)."""

    lo: float
    hi: float

    def __post_init__(self) -> None:
        if not (0 < self.lo < self.hi):
            raise SimulationInputError(f"--band {self.lo:g}:{self.hi:g}: give LO:HI in Hz with 0 < LO < HI")


@dataclass(frozen=True)
class StabilizationDiagram:
    """The poles of every order: order (-), frequency_hz (Hz), damping_ratio (-, after the window's damping is taken
    out) and status: 0 new, 1 stable in frequency, 2 stable in frequency and damping; one entry per pole."""

    order: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    status: np.ndarray
    max_order: int


@dataclass(frozen=True)
class Identification:
    """What `identify` finds: frequencies_hz (Hz), damping_ratios (-), modal_constants (n_outputs, n_modes; complex,
    1/kg for displacement per force), the outputs' names, the residuals, the stabilization diagram, the band, and the
    synthesized FRFs on the measured frequencies (synthesized[name])."""

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    modal_constants: np.ndarray
    names: list[str]
    diagram: StabilizationDiagram
    band: Band
    frequencies_fit_hz: np.ndarray
    synthesized: dict[str, np.ndarray] = field(default_factory=dict)
    lower_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))
    upper_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def complexity(self) -> np.ndarray:
        """|Im A| / |A| of each modal constant (-): 0 for a real (proportionally damped) mode."""
        return np.abs(self.modal_constants.imag) / np.maximum(np.abs(self.modal_constants), 1e-300)


def frequency_and_damping(poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies (Hz) and damping ratios (-) of poles lambda = -sigma + i omega_d (rad/s):
    omega_n = |lambda|, D = sigma / omega_n."""
    omega_n = np.abs(poles)
    return omega_n / (2 * np.pi), -poles.real / omega_n


def _toeplitz_sums(frequencies_hz: np.ndarray, frfs: np.ndarray, band: Band, max_order: int
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    """The sums r_m, s_m (per output), t_m (per output) for m = -n..n of LSCF's normal equations (module docstring),
    with the mapping's centre omega_c (rad/s) and period T (s)."""
    inside = (frequencies_hz >= band.lo) & (frequencies_hz <= band.hi)
    omega = 2 * np.pi * frequencies_hz[inside]
    H = frfs[:, inside]
    omega_c = np.pi * (band.lo + band.hi)
    T = BAND_FILL * np.pi / (np.pi * (band.hi - band.lo))
    z = np.exp(1j * (omega - omega_c) * T)
    weight2 = 1.0 / np.maximum(np.abs(H) ** 2, 1e-300)  # |w|^2 per output and line
    n = max_order
    r = np.zeros((H.shape[0], n + 1), complex)
    s = np.zeros((H.shape[0], 2 * n + 1), complex)
    t = np.zeros((H.shape[0], n + 1), complex)
    power = np.ones_like(z)
    wH = weight2 * H
    wHH = weight2 * np.abs(H) ** 2
    for m in range(n + 1):  # z^m for m >= 0; the negative powers are the conjugates (|z| = 1)
        r[:, m] = weight2 @ power
        t[:, m] = wHH @ power
        s[:, n + m] = -(wH @ power)
        s[:, n - m] = -(wH @ np.conj(power))
        power = power * z
    return r, s, t, omega_c, T


def lscf_poles(frequencies_hz: np.ndarray, frfs: np.ndarray, band: Band, max_order: int = MAX_ORDER
               ) -> list[np.ndarray]:
    """LSCF poles (rad/s, in the band and decaying) of every order 1..max_order (module docstring) of the FRFs
    (n_outputs, n_lines) measured at frequencies_hz (Hz)."""
    r, s, t, omega_c, T = _toeplitz_sums(frequencies_hz, frfs, band, max_order)
    n = max_order
    M = np.zeros((n + 1, n + 1), complex)
    for o in range(frfs.shape[0]):
        R = scipy.linalg.toeplitz(np.conj(r[o]), r[o])  # R[i, j] = r_(j - i)
        S = scipy.linalg.toeplitz(s[o, n::-1], s[o, n:])  # S[i, j] = s_(j - i)
        Tm = scipy.linalg.toeplitz(np.conj(t[o]), t[o])
        M += Tm - S.conj().T @ np.linalg.solve(R, S)
    poles_of_order = []
    for order in range(1, n + 1):
        block = M[: order + 1, : order + 1]
        try:
            alpha = np.linalg.solve(block[:order, :order], -block[:order, order])
        except np.linalg.LinAlgError:
            poles_of_order.append(np.zeros(0, complex))
            continue
        roots = np.roots(np.r_[1.0, alpha[::-1]])
        roots = roots[np.abs(roots) > 0]
        lam = np.log(roots) / T + 1j * omega_c
        f = lam.imag / (2 * np.pi)
        keep = (lam.real < 0) & (f >= band.lo) & (f <= band.hi)
        poles_of_order.append(np.sort_complex(lam[keep]))
    return poles_of_order


def stabilization(poles_of_order: list[np.ndarray], window_decay: float = 0.0) -> StabilizationDiagram:
    """The stabilization diagram of LSCF's poles (module docstring); damping ratios with the exponential window's
    decay rate window_decay (1/s) taken out."""
    orders, freqs, damps, status = [], [], [], []
    previous = None
    for order, poles in enumerate(poles_of_order, start=1):
        f, d = frequency_and_damping(poles + window_decay)
        fw, dw = frequency_and_damping(poles)
        for j in range(poles.size):
            state = 0
            if previous is not None and previous[0].size:
                k = int(np.argmin(np.abs(previous[0] - fw[j])))
                if abs(previous[0][k] / fw[j] - 1) < STABLE_FREQUENCY:
                    state = 1 + int(abs(previous[1][k] / dw[j] - 1) < STABLE_DAMPING)
            orders.append(order)
            freqs.append(f[j])
            damps.append(d[j])
            status.append(state)
        previous = (fw, dw)
    return StabilizationDiagram(np.array(orders, int), np.array(freqs), np.array(damps), np.array(status, int),
                                len(poles_of_order))


def stable_modes(diagram: StabilizationDiagram) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (Hz) and damping ratios (-) of the physical modes of a stabilization diagram: groups of stable
    poles (module docstring), medians over the upper half of each group's orders; ascending frequency."""
    stable = diagram.status == 2
    f, d, order = diagram.frequency_hz[stable], diagram.damping_ratio[stable], diagram.order[stable]
    sort = np.argsort(f)
    f, d, order = f[sort], d[sort], order[sort]
    if f.size == 0:
        return np.zeros(0), np.zeros(0)
    cuts = np.flatnonzero(np.diff(f) / f[1:] > CLUSTER_GAP) + 1
    need = max(3, int(np.ceil(MIN_SHARE * diagram.max_order)))
    out_f, out_d = [], []
    for group in np.split(np.arange(f.size), cuts):
        seen = np.unique(order[group])
        if seen.size < need:
            continue
        upper = group[order[group] >= np.median(seen)]
        if np.any(d[upper] <= 0):
            continue
        out_f.append(float(np.median(f[upper])))
        out_d.append(float(np.median(d[upper])))
    return np.array(out_f), np.array(out_d)


def lsfd(frequencies_hz: np.ndarray, frfs: np.ndarray, band: Band, natural_hz: np.ndarray, damping: np.ndarray
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """LSFD (module docstring): (modal constants (n_outputs, n_modes) complex, lower residuals, upper residuals (per
    output, complex), the synthesized FRFs (n_outputs, n_lines) on all of frequencies_hz)."""
    omega_all = 2 * np.pi * frequencies_hz
    wn = 2 * np.pi * np.asarray(natural_hz)

    def basis(omega: np.ndarray) -> np.ndarray:
        modal = 1.0 / (wn[None, :] ** 2 - omega[:, None] ** 2 + 2j * damping[None, :] * wn[None, :] * omega[:, None])
        return np.column_stack([modal, -1.0 / omega**2, np.ones_like(omega)])

    inside = (frequencies_hz >= band.lo) & (frequencies_hz <= band.hi)
    P = basis(omega_all[inside])
    n = wn.size
    constants = np.zeros((frfs.shape[0], n), complex)
    lower = np.zeros(frfs.shape[0], complex)
    upper = np.zeros(frfs.shape[0], complex)
    synthesized = np.zeros_like(frfs, dtype=complex)
    full = basis(omega_all)
    for o in range(frfs.shape[0]):
        H = frfs[o, inside]
        w = 1.0 / np.maximum(np.abs(H), 1e-300)
        coef = np.linalg.lstsq(P * w[:, None], H * w, rcond=None)[0]
        constants[o], lower[o], upper[o] = coef[:n], coef[n], coef[n + 1]
        synthesized[o] = full @ coef
    return constants, lower, upper, synthesized


def sub_bands(band: Band) -> list[tuple[Band, Band]]:
    """(fitted band, kept part) of each sub-band of `band` (module docstring); one pair (band, band) for a narrow band."""
    if band.hi / band.lo <= SEGMENT_SPAN**2:
        return [(band, band)]
    half_step = np.sqrt(SEGMENT_STEP)
    count = int(np.ceil(np.log(band.hi / band.lo) / np.log(SEGMENT_STEP)))
    centres = band.lo * half_step * SEGMENT_STEP ** np.arange(count)
    pairs = []
    for c in centres:
        kept = Band(max(band.lo, c / half_step), min(band.hi, c * half_step))
        if kept.lo < kept.hi:
            pairs.append((Band(max(band.lo, c / SEGMENT_SPAN), min(band.hi, c * SEGMENT_SPAN)), kept))
    return pairs


def sdypy_poles(frequencies_hz: np.ndarray, frfs: np.ndarray, band: Band, max_order: int = MAX_ORDER
                ) -> list[np.ndarray]:
    """The poles (rad/s, in the band and decaying) of sdypy-EMA's LSCF (real coefficients over 0..f_hi, the lines
    below f_lo set to zero; orders 2, 4, .. 2 max_order: max_order complex pairs) in the form of `lscf_poles`: the
    field's implementation, chosen with `ies identify --method sdypy` (needs pip install '.[measured]')."""
    import warnings

    try:
        from sdypy import EMA
    except ImportError:
        raise SimulationInputError("--method sdypy needs sdypy-EMA: pip install '.[measured]'") from None
    upto = frequencies_hz <= band.hi
    with warnings.catch_warnings():  # sdypy warns of a band edge between two lines; it takes the nearest
        warnings.simplefilter("ignore")
        model = EMA.Model(frf=frfs[:, upto], freq=frequencies_hz[upto], lower=band.lo, upper=band.hi,
                          pol_order_high=max_order, frf_form="receptance")
        model.get_poles(method="lscf", show_progress=False)
    out = []
    for f, zeta in zip(model.pole_freq, model.pole_xi):
        f, zeta = np.asarray(f, float), np.asarray(zeta, float)
        keep = np.isfinite(f) & np.isfinite(zeta) & (f >= band.lo) & (f <= band.hi) & (zeta > 0) & (zeta < 1)
        w = 2 * np.pi * f[keep]
        out.append(np.sort_complex(-zeta[keep] * w + 1j * w * np.sqrt(1 - zeta[keep] ** 2)))
    return out


#: the pole estimators of `ies identify --method`: name -> (poles of every order in `lscf_poles`' form, whether it fits
#: sub-bands, its orders per default order); sdypy-EMA's real-coefficient LSCF spans 0..f_hi and fits the whole band
#: at twice the order
METHODS = {"lscf": (lscf_poles, True, 1), "sdypy": (sdypy_poles, False, 2)}


def band_diagram(frequencies_hz: np.ndarray, frfs: np.ndarray, band: Band, max_order: int, window_decay: float,
                 source: str, method: str = "lscf") -> StabilizationDiagram:
    """The stabilization diagram of `band`: the poles of `method` (METHODS) of each sub-band up to max_order (lower
    where a sub-band holds fewer than 4 lines per order), each keeping the poles of its middle part (module
    docstring)."""
    poles_of, banded, factor = METHODS[method]
    parts = []
    max_order *= factor
    for fitted, kept in sub_bands(band) if banded else [(band, band)]:
        lines = int(np.sum((frequencies_hz >= fitted.lo) & (frequencies_hz <= fitted.hi)))
        order = min(max_order, lines // 4)
        if order < 4:
            continue
        d = stabilization(poles_of(frequencies_hz, frfs, fitted, order), window_decay)
        inside = (d.frequency_hz >= kept.lo) & (d.frequency_hz < kept.hi)
        parts.append((d.order[inside], d.frequency_hz[inside], d.damping_ratio[inside], d.status[inside]))
    if not parts:
        raise SimulationInputError(f"{source}: the band {band.lo:g}-{band.hi:g} Hz holds too few frequency lines for an "
                                   "identification (at least 16 a sub-band); widen --band or give a longer block")
    return StabilizationDiagram(*(np.concatenate(column) for column in zip(*parts)), max_order)


def identify(frequencies_hz: np.ndarray, frfs: np.ndarray, names: list[str], band: Band, *, modes: int | None = None,
             max_order: int = MAX_ORDER, window_decay: float = 0.0, source: str = "the FRFs",
             method: str = "lscf") -> Identification:
    """Modal parameters of FRFs of displacement per force (n_outputs, n_lines; m/N) at frequencies_hz (Hz) in `band`:
    LSCF (`method`: ours, or sdypy-EMA's) up to max_order in sub-bands, the stable poles chosen automatically (the `modes` with the highest peaks when
    given), damping with the exponential window's decay rate window_decay (1/s) taken out, LSFD for the modal constants
    over the whole band (module docstring). One line for a band outside the data or with too few lines, without a
    stable pole, and when fewer modes than `modes` are stable."""
    frequencies_hz = np.asarray(frequencies_hz, float)
    frfs = np.atleast_2d(np.asarray(frfs, complex))
    if band.hi <= frequencies_hz[0] or band.lo >= frequencies_hz[-1]:
        raise SimulationInputError(f"{source}: the band {band.lo:g}-{band.hi:g} Hz lies outside the measured "
                                   f"{frequencies_hz[0]:g}-{frequencies_hz[-1]:g} Hz; give --band inside it")
    diagram = band_diagram(frequencies_hz, frfs, band, max_order, window_decay, source, method)
    natural, damping = stable_modes(diagram)
    if natural.size == 0:
        raise SimulationInputError(f"{source}: no stable pole in {band.lo:g}-{band.hi:g} Hz (no mode, or the FRF is "
                                   "noise there); move --band onto the resonances or raise --max-order")
    if modes is not None and natural.size < modes:
        raise SimulationInputError(f"{source}: {natural.size} stable mode(s) in {band.lo:g}-{band.hi:g} Hz "
                                   f"({', '.join(f'{f:.5g} Hz' for f in natural)}) but --modes {modes}; widen --band, "
                                   "raise --max-order or ask fewer modes")
    constants, lower, upper, synthesized = lsfd(frequencies_hz, frfs, band, natural, damping)
    if modes is not None and natural.size > modes:
        peaks = np.sum(np.abs(constants), axis=0) / (2 * damping)  # the accelerance's peaks (module docstring)
        keep = np.sort(np.argsort(peaks)[::-1][:modes])
        natural, damping = natural[keep], damping[keep]
        constants, lower, upper, synthesized = lsfd(frequencies_hz, frfs, band, natural, damping)
    return Identification(natural, damping, constants, list(names), diagram, band, frequencies_hz,
                          synthesized={name: synthesized[o] for o, name in enumerate(names)}, lower_residual=lower,
                          upper_residual=upper)
