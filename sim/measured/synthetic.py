"""A synthetic measurement set of the host, made from the workbench's own linear model so that the whole path
identify -> update -> linearity -> design runs on data anyone can regenerate (`ies synthetic-tests`).

Hammer test (Appendix A): hits at the tip of the modal model (drive point phi_tip, responses the tip and the left
cavity wall: modal constants A_oj = phi_o,j phi_tip,j, 1/kg), each a half-sine force pulse (PULSE_S long); the
responses' accelerations are the exact response of each mode to the force interpolated linearly between the samples
of an OVERSAMPLING times finer grid (scipy's first-order-hold discretisation, filtered), and both channels go through
the same anti-aliasing filter and decimation to the sampling rate, like an analyser. Hits follow each other one block
apart, so every block ends while mode 1 still rings and the next block starts in that ringing; one hit has a second
pulse (a double hit); Gaussian noise of `noise` times each channel's RMS is added. A weak mode of the clamping above
mode 2 (CLAMP_MODE: the secondary peak of Fig. A.1) can be added.

Shaker test (Appendix B): the host alone under stepped-sine base excitation at several levels, mode 1 with a friction
element at the clamp: an Iwan element (IWAN_ELEMENTS Jenkins elements in parallel, each a spring in series with a
Coulomb slider) acting on mode 1's modal coordinate, with stiffness share kappa (their springs add kappa omega_1^2 in
stick, the linear model's omega_1 being the stuck frequency) and slip tip amplitudes log-spaced over IWAN_SLIP_M (m).
Each frequency step is integrated in time (the linear part exactly per step with the forces linear in it, the
friction at the step's end by one predictor-corrector pass, STEPS_PER_PERIOD steps per period) from the describing
function's steady state (the sliders set by driving them through that cycle's extremes) over SETTLE_PERIODS periods;
the last AVERAGE_PERIODS give the fundamental harmonic. Modes 2.. add their linear response. The known
amplitude-dependent frequency and damping of this element (its describing function, `iwan_backbone`) is what
`ies linearity` must find (tests/sim/measured/test_linearity.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.measured.hammer import HammerRecord

PULSE_S = 1.5e-4
OVERSAMPLING = 8
#: the clamping's mode: (frequency over mode 2's, modal constant over mode 2's, damping ratio)
CLAMP_MODE = (1.06, 0.02, 0.005)
IWAN_ELEMENTS = 12
STEPS_PER_PERIOD = 128
SETTLE_PERIODS = 300
AVERAGE_PERIODS = 40


@dataclass(frozen=True)
class HammerTest:
    """What a synthetic hammer test is made of: natural frequencies (Hz), damping ratios (-), modal constants
    (n_responses, n_modes; 1/kg) with the responses' names; fs (Hz), block (samples per hit), hits, the peak force
    (N), noise (share of each channel's RMS), the hit with a double hit (index, or None) and the seed."""

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    modal_constants: np.ndarray
    names: tuple[str, ...]
    fs: float = 16384.0
    block: int = 2**15
    hits: int = 6
    peak_force: float = 100.0
    noise: float = 0.01
    double_hit: int | None = 2
    seed: int = 1


def hammer_record(test: HammerTest) -> HammerRecord:
    """The continuous record of a synthetic hammer test (module docstring): force (N) and accelerations (m/s^2)."""
    import scipy.signal

    rng = np.random.default_rng(test.seed)
    fine = test.fs * OVERSAMPLING
    n = (test.block * test.hits + test.block // 4) * OVERSAMPLING
    t = np.arange(n) / fine
    force = np.zeros(n)
    for i in range(test.hits):
        t0 = (i * test.block + test.block // 8 + rng.integers(0, 64)) / test.fs
        pulses = [(test.peak_force * (0.9 + 0.2 * rng.random()), t0)]
        if i == test.double_hit:
            pulses.append((0.3 * test.peak_force, t0 + 4e-3))
        for amplitude, start in pulses:
            inside = (t >= start) & (t <= start + PULSE_S)
            force[inside] += amplitude * np.sin(np.pi * (t[inside] - start) / PULSE_S)
    responses = {}
    for o, name in enumerate(test.names):
        acc = np.zeros(n)
        for f, D, A in zip(test.frequencies_hz, test.damping_ratios, test.modal_constants[o]):
            w = 2 * np.pi * f
            system = (np.array([[0.0, 1.0], [-w * w, -2 * D * w]]), np.array([[0.0], [A]]),
                      np.array([[-w * w, -2 * D * w]]), np.array([[A]]))
            Ad, Bd, Cd, Dd, _ = scipy.signal.cont2discrete(system, 1 / fine, method="foh")
            num, den = scipy.signal.ss2tf(Ad, Bd, Cd, Dd)
            acc += scipy.signal.lfilter(num[0], den, force)
        responses[name] = acc

    def analyser(x: np.ndarray) -> np.ndarray:
        y = scipy.signal.decimate(x, OVERSAMPLING, ftype="fir", zero_phase=True)
        return y + test.noise * np.sqrt(np.mean(y**2)) * rng.standard_normal(y.size)

    return HammerRecord(test.fs, analyser(force), {k: analyser(v) for k, v in responses.items()},
                        {k: "acceleration" for k in responses}, "synthetic hammer test")


@dataclass(frozen=True)
class Iwan:
    """The friction element at the clamp (module docstring): omega_1 (rad/s, the stuck frequency), phi_tip of mode 1
    (1/sqrt(kg)), the stiffness share kappa (-) and the slip tip amplitudes of its elements (m)."""

    omega_1: float
    phi_tip: float
    kappa: float
    slips: np.ndarray

    @property
    def stiffness(self) -> float:
        """Each element's modal stiffness (1/s^2)."""
        return self.kappa * self.omega_1**2 / self.slips.size

    @property
    def slip_modal(self) -> np.ndarray:
        """Each element's slip displacement in mode 1's modal coordinate (m sqrt(kg))."""
        return self.slips / self.phi_tip


def iwan_backbone(iwan: Iwan, D_lin: float, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The describing function of the host with the Iwan element: omega(a) (rad/s) and D(a) (-) at tip amplitudes a (m),
    D_lin the linear modal damping ratio (viscous, 2 D_lin omega_1). Each element (stiffness k, slip x) at modal
    amplitude X > x: beta = arccos(1 - 2 x / X), equivalent stiffness k (beta - sin(2 beta) / 2) / pi, energy lost per
    cycle 4 k x (X - x); in stick (X <= x): k and 0."""
    X = np.atleast_1d(np.asarray(a, float)) / iwan.phi_tip
    k = iwan.stiffness
    keq = np.zeros_like(X)
    lost = np.zeros_like(X)
    for x in iwan.slip_modal:
        slip = X > x
        beta = np.arccos(np.clip(1 - 2 * x / np.where(slip, X, 1e300), -1, 1))
        keq += np.where(slip, k * (beta - 0.5 * np.sin(2 * beta)) / np.pi, k)
        lost += np.where(slip, 4 * k * x * (X - x), 0.0)
    omega = np.sqrt(iwan.omega_1**2 * (1 - iwan.kappa) + keq)
    c = 2 * D_lin * iwan.omega_1 + lost / (np.pi * omega * X**2)
    return omega, c / (2 * omega)


def shaker_levels(iwan: Iwan, D_lin: float, gamma: float, frequencies_hz: np.ndarray, a_bases: np.ndarray,
                  background: np.ndarray | None = None) -> np.ndarray:
    """Complex tip amplitudes relative to the base (m), (levels, steps), of stepped sines at the frequencies (Hz) and
    base amplitudes a_bases (m): mode 1 (participation gamma, sqrt(kg)) with the Iwan element integrated in time
    (module docstring), plus `background` (complex, per m of a_base at each frequency: the other modes' linear
    response)."""
    from sim.measured.linearity import balance_roots

    steps = np.asarray(frequencies_hz, float)
    a_grid = np.geomspace(1e-7, 1e-2, 600)
    w_grid, D_grid = iwan_backbone(iwan, D_lin, a_grid)
    omega_of = lambda a: np.interp(a, a_grid, w_grid)  # noqa: E731
    damping_of = lambda a: np.interp(a, a_grid, D_grid)  # noqa: E731
    start = np.zeros((len(a_bases), steps.size), complex)
    for lv, a_base in enumerate(a_bases):  # the describing function's steady state, stepping up in frequency
        previous = None
        for i, W in enumerate(2 * np.pi * steps):
            roots = balance_roots(omega_of, damping_of, iwan.phi_tip * gamma, W, a_base, 1e-2)
            a = roots[np.argmin(np.abs(roots - previous))] if previous is not None else roots.max()
            previous = a
            w, D = omega_of(a), damping_of(a)
            start[lv, i] = gamma * W**2 * a_base / (w**2 - W**2 + 2j * D * w * W)
    Omega = np.broadcast_to(2 * np.pi * steps, start.shape).ravel()
    force = gamma * Omega**2 * np.repeat(np.asarray(a_bases, float), steps.size)
    S = start.ravel()
    w_m2 = iwan.omega_1**2 * (1 - iwan.kappa)
    c = 2 * D_lin * iwan.omega_1
    k, xs = iwan.stiffness, iwan.slip_modal[:, None]
    s, v = S.real.copy(), (1j * Omega * S).real.copy()
    z = np.zeros((xs.size, Omega.size))

    def friction(position: np.ndarray, sliders: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        stretch = position[None, :] - sliders
        sliders = np.where(np.abs(stretch) > xs, position[None, :] - np.sign(stretch) * xs, sliders)
        return k * np.sum(position[None, :] - sliders, axis=0), sliders

    # the sliders as on the describing function's cycle: driven through its extremes to the start (Masing)
    X = np.abs(S)
    for position in (X, -X, np.where(v < 0, X, -X), s):
        f_now, z = friction(position, z)
    # the linear part exact over a step, the forces linear in it (first-order hold): x' = Phi x + G0 u_k + G1 u_k+1
    Phi, G0, G1 = _first_order_hold(w_m2, c, 1.0 / (steps * STEPS_PER_PERIOD))
    Phi, G0, G1 = (np.concatenate([m] * len(a_bases)) for m in (Phi, G0, G1))
    x = np.stack([s, v], axis=1)
    coef = np.zeros(Omega.size, complex)
    delta = 2 * np.pi / STEPS_PER_PERIOD
    for step in range(1, (SETTLE_PERIODS + AVERAGE_PERIODS) * STEPS_PER_PERIOD + 1):
        phase = step * delta
        base = np.einsum("nij,nj->ni", Phi, x) + G0 * (force * np.cos(phase - delta) - f_now)[:, None]
        guess = base + G1 * (force * np.cos(phase) - f_now)[:, None]  # predictor: the friction held
        f_guess, _ = friction(guess[:, 0], z)
        x = base + G1 * (force * np.cos(phase) - f_guess)[:, None]  # corrector: the friction at the predicted end
        f_now, z = friction(x[:, 0], z)
        if step > SETTLE_PERIODS * STEPS_PER_PERIOD:
            coef += x[:, 0] * np.exp(-1j * phase)
    tip = iwan.phi_tip * 2 * coef / (AVERAGE_PERIODS * STEPS_PER_PERIOD)
    tip = tip.reshape(start.shape)
    if background is not None:
        tip = tip + background[None, :] * np.asarray(a_bases, float)[:, None]
    return tip


#: Table A.1: the measured frequencies (Hz) and damping ratios (-) of modes 1-4 the synthetic rig is given
TABLE_A1_HZ = (117.4, 886.0, 2494.0, 4712.0)
TABLE_A1_DAMPING = (0.0006, 0.0044, 0.0005, 0.0031)
#: Appendix B's base amplitudes (m), times LEVEL_FACTOR: the built-in beam's phi_tip Gamma (1.43) is smaller than the
#: rig's, and this factor makes its tip amplitudes span the paper's range of interest, 0.58-0.95 mm
LEVELS_PAPER = (2.0e-7, 2.7e-7, 4.7e-7, 6.7e-7, 9.4e-7)
LEVEL_FACTOR = 1.4
#: the friction element at the clamp: stiffness share and the range of the slip tip amplitudes (m)
IWAN_KAPPA = 0.0045
IWAN_SLIP_M = (0.2e-3, 3e-3)
#: the stepped sine: eta range around f_1 and steps
SHAKER_ETA = (0.992, 1.004)
SHAKER_STEPS = 49


def _first_order_hold(w2: float, c: float, dt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Phi, G0, G1) per step length dt (s) of s'' + c s' + w2 s = u with u linear over the step: the exact
    x_k+1 = Phi x_k + G0 u_k + G1 u_k+1, x = (s, s'), from the exponential of the augmented matrix."""
    import scipy.linalg

    A = np.array([[0.0, 1.0], [-w2, -c]])
    out = []
    for h in np.atleast_1d(dt):
        M = np.zeros((4, 4))
        M[:2, :2], M[1, 2], M[2, 3] = A, 1.0, 1.0 / h
        E = scipy.linalg.expm(M * h)
        out.append((E[:2, :2], E[:2, 2] - E[:2, 3], E[:2, 3]))
    return tuple(np.array(m) for m in zip(*out))


def rig_truth() -> dict:
    """The synthetic rig: the built-in model's mode values with Table A.1's frequencies and damping for modes 1-4 (the
    rest as the model, 0.1 %), the clamping's mode, and the friction element at the clamp."""
    from sim.hosts.rig import seed_rig_model

    model = seed_rig_model()
    f = np.array(model.frequencies_hz)
    D = np.array(model.damping_ratios)
    f[:4], D[:4] = TABLE_A1_HZ, TABLE_A1_DAMPING
    D[4:] = 0.001
    ratio, share, damping = CLAMP_MODE
    return {"model": model, "frequencies_hz": f, "damping_ratios": D,
            "clamp_mode": (ratio * f[1], share * model.phi_tip[1] ** 2, damping),
            "iwan": Iwan(2 * np.pi * f[0], float(model.phi_tip[0]), IWAN_KAPPA,
                         np.geomspace(*IWAN_SLIP_M, IWAN_ELEMENTS))}


def write_rig_test_set(folder, seed: int = 1) -> list:
    """The synthetic measurement set of the rig in `folder` (module docstring): hammer.csv (6 hits of 2^15 samples at
    16.384 kHz, tip and left-wall accelerations, 1 % noise, a double hit at the third hit), level-1.csv ...
    level-5.csv (stepped sines of the host alone, 1 % noise) and truth.json (what they were made of). About 5 s."""
    from pathlib import Path

    from sim.common.files import dumps, write_text

    folder = Path(folder)
    truth = rig_truth()
    model = truth["model"]
    clamp_f, clamp_A, clamp_D = truth["clamp_mode"]
    drive = model.phi_tip
    constants = np.array([model.phi_tip * drive, model.phi_wall_left * drive])
    test = HammerTest(np.r_[truth["frequencies_hz"], clamp_f], np.r_[truth["damping_ratios"], clamp_D],
                      np.column_stack([constants, [clamp_A, clamp_A * model.phi_wall_left[1] / model.phi_tip[1]]]),
                      ("tip", "wall"), seed=seed)
    order = np.argsort(test.frequencies_hz)
    test = HammerTest(test.frequencies_hz[order], test.damping_ratios[order], test.modal_constants[:, order],
                      test.names, seed=seed)
    record = hammer_record(test)
    t = np.arange(record.force.size) / record.fs
    table = np.column_stack([t, record.force, record.responses["tip"], record.responses["wall"]])
    written = [write_text(folder / "hammer.csv", "time_s,force_N,tip_m_s2,wall_m_s2\n"
                          + "\n".join(f"{row[0]:.9g}," + ",".join(f"{v:.7g}" for v in row[1:]) for row in table) + "\n")]
    iwan = truth["iwan"]
    steps = truth["frequencies_hz"][0] * np.linspace(*SHAKER_ETA, SHAKER_STEPS)
    W = 2 * np.pi * steps[:, None]
    wj, Dj = 2 * np.pi * truth["frequencies_hz"][1:], truth["damping_ratios"][1:]
    background = np.sum(model.phi_tip[1:] * model.participation[1:] * W**2
                        / (wj**2 - W**2 + 2j * Dj * wj * W), axis=1)
    a_bases = LEVEL_FACTOR * np.array(LEVELS_PAPER)
    tip = shaker_levels(iwan, float(truth["damping_ratios"][0]), float(model.participation[0]), steps, a_bases,
                        background)
    rng = np.random.default_rng(seed + 1)
    tip = tip * (1 + 0.01 * (rng.standard_normal(tip.shape) + 1j * rng.standard_normal(tip.shape)) / np.sqrt(2))
    for i, a_base in enumerate(a_bases):
        rows = [f"{f:.8g},{abs(x):.7g},{np.degrees(np.angle(x)):.6g},{a_base:.6g}" for f, x in zip(steps, tip[i])]
        written.append(write_text(folder / f"level-{i + 1}.csv", "frequency_Hz,amplitude_m,phase_deg,a_base_m\n"
                                  + "\n".join(rows) + "\n"))
    a = np.linspace(0.2e-3, 1.1e-3, 19)
    omega, D = iwan_backbone(iwan, float(truth["damping_ratios"][0]), a)
    in_range = np.linspace(0.58e-3, 0.95e-3, 201)
    D_range = iwan_backbone(iwan, float(truth["damping_ratios"][0]), in_range)[1]
    written.append(write_text(folder / "truth.json", dumps({
        "made_by": "ies synthetic-tests (sim.measured.synthetic)", "seed": seed,
        "hammer": {"frequencies_hz": test.frequencies_hz, "damping_ratios": test.damping_ratios,
                   "modal_constants_per_kg": {"tip": test.modal_constants[0], "wall": test.modal_constants[1]},
                   "clamp_mode_hz": clamp_f, "fs_hz": test.fs, "block": test.block, "hits": test.hits,
                   "double_hit": test.double_hit, "noise": test.noise},
        "shaker": {"a_base_m": a_bases, "kappa": iwan.kappa, "slip_tip_amplitudes_m": iwan.slips,
                   "linear_damping_ratio": truth["damping_ratios"][0], "noise": 0.01,
                   "backbone": {"amplitude_m": a, "frequency_hz": omega / (2 * np.pi), "damping_ratio": D},
                   "damping_interval_0.58_0.95mm": [float(D_range.min()), float(D_range.max())]},
        "model": model.source}) + "\n"))
    return written
