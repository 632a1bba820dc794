"""Toy maps with bifurcations known in closed form, run through the orbits' own continuation and detection
(`sim.orbits.continuation.Continuer` takes any map with the interface of `sim.orbits.shooting.ShootingMap`).

Each toy is a map of the plane per excitation period, y = (x, w) with w contracted by CONTRACTION so that one
multiplier is always well inside, and a parameter p:

* fold:            x -> x + p - x^2                 fixed points x = +-sqrt(p), multiplier 1 - 2x: a fold at p = 0;
* transcritical:   x -> x + p x - x^2               x = 0 and x = p cross at p = 0, multiplier 1 + p on x = 0;
* period doubling: x -> -(1 + p) x + x^3            x = 0, multiplier -(1 + p); the 2-cycle x^2 = p for p > 0;
* symmetric:       the half map G: x -> -(1 + p) x + x^3 (the toy's symmetric orbits are G's fixed points,
                   P = G o G): G's multiplier -(1 + p) breaks the symmetry at p = 0, P's asymmetric fixed points
                   are x^2 = p (mirror images of each other: G(x) = -x);
* Neimark-Sacker:  z -> (1 + p) e^{i THETA} z - |z|^2 z   (z = x + i w), multipliers (1 + p) e^{+-i THETA};
* grazing:         x -> p + A x + (B - A) h(x - EDGE), h = 0 below the edge and h' = min(1, sqrt(d / WIDTH)) above
                   it (C^1, like the Hertz contact's force, with an "impact" more above the edge): the fixed point
                   x = p / (1 - A) reaches the edge at p = EDGE (1 - A), and within WIDTH above it the multiplier
                   jumps from A = 0.5 (stable) to B = -1.5 (through -1 there, in a jump: a grazing, not a period
                   doubling).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from sim.orbits.setting import Parameter
from sim.orbits.shooting import MapValue, ShootingMap

CONTRACTION = 0.5
THETA = 1.1
EDGE, A, B, WIDTH = 0.4, 0.5, -1.5, 1e-4


@dataclass(frozen=True)
class ToySetting:
    """A toy's parameter p and which toy (module docstring); the attributes the orbits' code reads."""

    kind: str
    p: float
    level: float = 1.0
    eta: float = 1.0
    a_noabs: float = 1.0
    integrator: str = "toy"

    @property
    def symmetric_walls(self) -> bool:
        return self.kind == "symmetric"

    def scales(self) -> np.ndarray:
        return np.ones(2)

    def system(self) -> None:
        return None

    def period_map(self, y: np.ndarray) -> np.ndarray:
        """One period of the toy (for "symmetric": its half map G)."""
        x, w = y
        p = self.p
        if self.kind == "fold":
            x = x + p - x * x
        elif self.kind == "transcritical":
            x = x + p * x - x * x
        elif self.kind in ("period-doubling", "symmetric"):
            x = -(1.0 + p) * x + x**3
        elif self.kind == "neimark-sacker":
            z = complex(x, w)
            z = (1.0 + p) * np.exp(1j * THETA) * z - abs(z) ** 2 * z
            return np.array([z.real, z.imag])
        elif self.kind == "grazing":
            d = max(x - EDGE, 0.0)
            h = 2.0 / 3.0 * d**1.5 / math.sqrt(WIDTH) if d < WIDTH else 2.0 / 3.0 * WIDTH + (d - WIDTH)
            x = p + A * x + (B - A) * h
        return np.array([x, CONTRACTION * w])

    def events(self, y: np.ndarray) -> int:
        """The toy's "impacts" in one period from y: one, and one more above the grazing toy's edge."""
        return 2 if self.kind == "grazing" and y[0] > EDGE else 1


class ToyMap(ShootingMap):
    """A toy's k-period map with the interface of `ShootingMap` (its residual and Jacobian are ShootingMap's)."""

    def __init__(self, setting: ToySetting, k: int = 1, *, system: object = None) -> None:
        self.setting, self.k, self.sys = setting, int(k), None
        self.scale = setting.scales()
        self.evaluations = 0
        self.fd_step = 1e-7

    def retarget(self, setting: ToySetting) -> None:
        self.setting = setting

    def __call__(self, y: np.ndarray) -> MapValue:
        self.evaluations += 1
        s = self.setting
        state = np.array(y, dtype=float)
        if s.kind == "symmetric":  # P = G o G; the state at k T / 2 is (-1)^k G^k (y)
            half = state.copy()
            for _ in range(self.k):
                half = s.period_map(half)
            half = -half if self.k % 2 else half
            end = state
            for _ in range(2 * self.k):
                end = s.period_map(end)
            events = np.ones(self.k, dtype=np.int64)
            amplitudes = np.full(self.k, abs(state[0]))
            return MapValue(end, half, amplitudes, events)
        states = [state]
        for _ in range(self.k):
            states.append(s.period_map(states[-1]))
        half = states[self.k // 2] if self.k % 2 == 0 else np.full(2, np.nan)
        return MapValue(states[-1], half, np.abs(np.array([y_[0] for y_ in states[:-1]])),
                        np.array([s.events(y_) for y_ in states[:-1]], dtype=np.int64))

    def pattern(self, y: np.ndarray) -> tuple[str, float]:
        return "", math.nan

    def clearance(self, y: np.ndarray) -> float:
        """The grazing toy's distance to its edge from below over the k periods (inf above it)."""
        states, smallest = [np.array(y, float)], math.inf
        for _ in range(self.k):
            if states[-1][0] < EDGE:
                smallest = min(smallest, EDGE - states[-1][0])
            states.append(self.setting.period_map(states[-1]))
        return smallest


def _get(setting: ToySetting) -> float:
    return setting.p


def _set(setting: ToySetting, value: float) -> ToySetting:
    return replace(setting, p=float(value))


#: The toys' continuation parameter p.
P = Parameter("p", "-", _get, _set, scale=1.0)
