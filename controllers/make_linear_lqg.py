"""Write ``linear_lqg.npz``, the saved compensator of ``linear.toml``.

The compensator is the LQG of ``lqg.toml`` designed once at 1.1 x the open-loop flutter speed
on the loop of ``scenarios/goland_aileron_lqg.toml`` (Goland wing with the illustrative
aileron, 10 elements, sea level, 20 design modes, the 3rd-order aileron servo, 1 kHz), taken
out of aeroservo as a black box: the discrete ``control.StateSpace`` from the three tip
sensors to the hinge-moment command, saved as any other tool would save it (see
``aeroservo.files.linear_controller``). Run from anywhere, with aeroservo installed::

    python controllers/make_linear_lqg.py
"""

from pathlib import Path

import numpy as np

import aeroservo as aes
from aeroservo.files import load_controller, load_scenario

HERE = Path(__file__).resolve().parent

scenario = load_scenario(HERE.parent / "scenarios" / "goland_aileron_lqg.toml")
model = scenario.model()
vf = aes.flutter_boundary(model, scenario.density).flutter_speed  # 137.37 m/s
speed = 1.1 * vf  # design speed [m/s]
loop = scenario.loop(model)
spec = load_controller(HERE / "lqg.toml")
schedule = loop.design_controller(spec, speed, scenario.sample_rate, vf)
K = schedule.at(speed).compensator  # discrete, dt = 1 ms; its output is the command (sign = 1)
np.savez(
    HERE / "linear_lqg.npz",
    A=K.A,
    B=K.B,
    C=K.C,
    D=K.D,
    dt=K.dt,  # [s]
    inputs=K.input_labels,  # sensors: tip_le_accel [m/s^2], tip_te_accel [m/s^2], tip_twist [rad]
    outputs=K.output_labels,  # command: aileron_hinge_moment [N m]
)
print(f"wrote {HERE / 'linear_lqg.npz'}: {K.nstates} states, dt = {K.dt} s")
