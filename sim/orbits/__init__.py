"""Periodic orbits of the full model (seed paper Eqs. 3-7, 10) with their stability and bifurcations: shooting on the
exact integrator, pseudo-arclength continuation in eta, the level and other parameters, Floquet multipliers,
bifurcation detection and branch switching, and the command `ies orbits`.

Parts, in the order they build on each other:
  setting        one point of parameter space (`OrbitSetting`) and the continuation parameters
  shooting       the k-period and half-period maps, their Jacobian, Newton's method, the orbit record
  starts         the linear solution, the slow flow's orbit carried to the full model, a simulated state
  continuation   pseudo-arclength continuation with step control
  bifurcations   multipliers' crossings, folds, grazing; their location and labels; branch switching
  response       the frequency response (or level curve) of one level: start, branches, switching, linear orbits
  tables         orbits.csv, results.nc, orbits.json
  figures        the figure (stable solid, unstable dashed, bifurcations, shading, stepped-sine points)
  cli            `ies orbits` (registered by `sim.cli`)

The one-mode Newton model's orbits stay in `sim.reduced.slow_flow` (`exact_orbit`, `orbit_map`); this package
starts from them (`sim.orbits.starts`).
"""
