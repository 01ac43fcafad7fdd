"""Library use without the command line: the reference clutch end to end.

Run:  python examples/notebook_example.py
"""

import matplotlib

matplotlib.use("Agg")

import rattle

model = rattle.reference_case()

# Every branch, stable and unstable, with the period-doubled ones and the named regions.
frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32, subharmonics=True)
print(frf.summary())

# The rig's view: a run-up and a run-down, state carried from speed to speed.
sweep = rattle.time_sweep(model, omega=(0.1, 3.0), points=100, direction="both")
for jump in sweep.jumps():
    print(jump)

# All orbits coexisting at one speed inside the hysteresis of the primary resonance.
orbit = rattle.periodic_orbit(model, 0.8)
print(orbit.summary())

fig, ax = frf.plot()
fig.savefig("frf_example.png", dpi=110)
