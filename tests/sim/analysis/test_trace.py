"""Acceptance of the signal analyses on traces of `ies trace` (the rig at a_base/a_base* = 7.4, 51.2 kHz,
eta 0.976 and 0.99): the detector of Appendix D.1 against the simulator's own contacts, the Eq. 9 fit
against the simulator's modal energies after impacts, and why the 20 kHz high-pass fails on these traces."""
import numpy as np
import pytest

from sim.analysis.impacts import detect_impacts, envelope, match_impacts, zero_phase_filter
from sim.analysis.modal_fit import fit_modes
from sim.stepped_sine.protocol import SteppedSine
from sim.hosts.rig import seed_rig_model
from sim.analysis.signals import make_signal
from sim.model.system import Impactor
from sim.analysis.trace import record_trace

#: Far enough above the rig's mode 9 (19.83 kHz) that its ringing stays below the threshold at both points: the
#: zero-phase high-pass passes 43 % of its amplitude at the paper's 20 kHz, 12.5 % at 21 kHz (enough for 52 %
#: false detections at eta 0.99, where the impacts are stronger), 1.8 % at 22 kHz.
HIGHPASS = 22e3


@pytest.fixture(scope="module", params=[0.976, 0.99])
def trace(request):
    """The trace `ies trace --level 7.4 --eta ETA` records (default wait, 50 periods, 51.2 kHz)."""
    model = seed_rig_model(9)
    return record_trace(model, Impactor(), 7.4, SteppedSine(eta_start=request.param, eta_stop=request.param, n_eta=1)), model


def _modal_energies(trace, times):
    """E_j = (s_j'^2 + omega_j^2 s_j^2) / 2 of the recorded states at times (s) on the sample grid."""
    model = trace[1]
    n = model.n_modes
    rows = trace[0].states[np.rint(np.asarray(times) * trace[0].fs).astype(int)]
    return 0.5 * (rows[:, n:2 * n] ** 2 + (model.omega * rows[:, :n]) ** 2)


def test_detector_agrees_with_the_simulator_above_the_threshold(trace):
    """>= 95 % of the contacts above the nominal threshold found within 0.2 ms, <= 5 % false detections.
    Above the threshold: the contact's own impulsive part of the wall acceleration (the direct term
    -(phi_l^T phi_l f_l + phi_l^T phi_r f_r) of Eq. 7), high-passed like the signal, peaks above it."""
    tr, model = trace
    s = tr.signal
    found = detect_impacts(s, [1.0], excitation_hz=tr.Omega / (2 * np.pi), highpass_hz=HIGHPASS)
    from sim.model.system import system_arrays

    sys = system_arrays(model, Impactor())
    direct = -(sys.phi_l @ sys.phi_l) * s["f_left"] - (sys.phi_l @ sys.phi_r) * s["f_right"]
    own = envelope(zero_phase_filter(direct, s.fs, HIGHPASS, "highpass"))
    contacts = tr.contacts
    above = np.array([own[a:b + 2].max() for a, b in zip(contacts.first, contacts.last)]) >= found.reference_rms
    pairs = match_impacts(found.times, contacts.times, 2e-4)
    matched = np.zeros(contacts.times.size, bool)
    matched[pairs[:, 1]] = True
    false_share = 1 - pairs.shape[0] / found.times.size
    print(f"\neta {tr.eta}: {contacts.times.size} contacts, {above.sum()} above the threshold, "
          f"{100 * matched[above].mean():.1f} % of them found, {found.times.size} detections, "
          f"{100 * false_share:.1f} % false; all contacts found {100 * matched.mean():.1f} %")
    assert above.sum() >= 10  # 16-56 on different machines (chaotic response): >= 95 % found then means all
    assert matched[above].mean() >= 0.95 and false_share <= 0.05


def test_modal_fit_recovers_the_simulators_energies(trace):
    """With the simulator's contacts and with the detector's impacts: every well-posed window's E_j within 2 %
    (mode 1) and 10 % (modes 2..9) of the recorded state's (in fact ~1e-6), and the share of modes 2..9."""
    tr, model = trace
    f = tr.Omega / (2 * np.pi)
    for given in (tr.contacts.times, None):
        fit = fit_modes(tr.signal, model, given, excitation_hz=f, highpass_hz=HIGHPASS)
        good = [w for w in fit.windows if w.well_posed]
        assert len(good) >= 10
        true = _modal_energies(trace, [w.start for w in good])
        error = np.abs(np.array([w.energies for w in good]) / true - 1)
        share = true[:, 1:].sum() / true.sum()
        print(f"\neta {tr.eta} ({'simulator' if given is not None else 'detector'}): {len(good)} of {len(fit.windows)} "
              f"windows, error mode 1 {error[:, 0].max():.1e}, modes 2..9 {error[:, 1:].max():.1e}; share of modes "
              f"2..9 fitted {100 * fit.higher_share:.2f} %, simulated {100 * share:.2f} %")
        assert error[:, 0].max() <= 0.02 and error[:, 1:].max() <= 0.10
        assert fit.higher_share == pytest.approx(share, rel=1e-3)


def test_the_20_kHz_high_pass_counts_the_ringing_of_mode_9(trace):
    """At the paper's 20 kHz most detections on a simulated trace are false (83 % at eta 0.976, 91 % at 0.99);
    the same wall accelerations without mode 9's part give none at 0.976 and 23 % at 0.99: the lightly damped
    (D = 0.1 %) mode 9 at 19.83 kHz, 0.9 % below the cut-off, passes the zero-phase 4th-order high-pass with
    43 % of its amplitude and rings for ~8 ms after each impact. The sampled force spikes are in both signals."""
    tr, model = trace
    s = tr.signal
    f = tr.Omega / (2 * np.pi)
    from sim.model.system import system_arrays

    sys = system_arrays(model, Impactor())
    y, n = tr.states, model.n_modes
    phase = 2 * np.pi * np.arange(y.shape[0]) / tr.samples_per_period
    base = -tr.a_base * tr.Omega**2 * np.cos(phase)
    modal = (-2 * sys.D * sys.omega * y[:, n:2 * n] - sys.omega**2 * y[:, :n] - np.outer(s["f_left"], sys.phi_l)
             - np.outer(s["f_right"], sys.phi_r) - np.outer(base, sys.gamma))
    np.testing.assert_allclose(modal @ sys.phi_l + base, s["a_left"], atol=1e-9 * np.abs(s["a_left"]).max())
    shares = {}
    for label, keep in (("all modes", slice(None)), ("without mode 9", slice(0, n - 1))):
        walls = {w: modal[:, keep] @ getattr(sys, f"phi_{w[2]}")[keep] + base for w in ("a_left", "a_right")}
        signal = make_signal(s.t, {**walls, "a_tip": s["a_tip"]})
        found = detect_impacts(signal, [1.0], excitation_hz=f)
        shares[label] = 1 - match_impacts(found.times, tr.contacts.times, 2e-4).shape[0] / found.times.size
    print(f"\neta {tr.eta}, 20 kHz: false detections {100 * shares['all modes']:.0f} %, "
          f"without mode 9 {100 * shares['without mode 9']:.0f} %")
    assert shares["all modes"] > 0.5 and shares["without mode 9"] < shares["all modes"] / 3
    if tr.eta == 0.976:
        assert shares["without mode 9"] <= 0.05
