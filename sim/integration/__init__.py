"""Time integrators of Eqs. 3-7 (Sect. 3.2): the numba kernels and their cache (`jit`), the exact free-flight
integrator with located contacts (`exact`, `collocation`, `dopri5`, `flight`), the paper's fixed-step ode3, the
energy ledger, the integrators as records of their capabilities (`integrators.INTEGRATORS`), and independent scipy
references for the tests."""
