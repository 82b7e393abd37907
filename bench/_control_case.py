"""The closed-loop benchmark case shared by ``bench_control.py`` and ``bench_mpc.py``.

Goland wing with the illustrative aileron, 10 elements, 1.225 kg/m^3, 1.1 x its open-loop flutter
speed, 1 kHz, hinge-moment limits 2000 N m and 2e5 N m/s, initial state: the static shape with a
0.2 m tip deflection (enough for the limits to be hit).
"""

from __future__ import annotations

import numpy as np

import aeroservo as aes
from aeroservo._c_stdout import c_stdout_silenced as quiet_stdout  # noqa: F401 (re-export)
from aeroservo.design import (
    Bryson,
    Limits,
    lqr_controller,
    state_map,
    with_sensor_filters,
)
from aeroservo.linear.models import tip_deflection_state

RHO = 1.225
DT = 1e-3
CONTROL = "aileron_hinge_moment"
SENSORS = ["tip_le_accel", "tip_te_accel", "tip_twist"]
TIP = 0.2  # initial tip deflection [m]


def build() -> dict:
    wing = aes.examples.goland_aileron()
    model = aes.AeroelasticModel(wing, 10)
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    speed = 1.1 * vf
    ins = [CONTROL, "gust"]
    outs = ["tip_le_accel", "tip_te_accel", "tip_twist", "tip_disp", "aileron_deflection"]
    pb = aes.StateSpaceBuilder(model, RHO, ins, outs)
    db = aes.StateSpaceBuilder(model, RHO, ins, outs, n_modes=8)
    plant, design = pb.at(speed), db.at(speed)
    bryson = Bryson(outputs={"tip_disp": 0.05, "tip_twist": 0.02}, inputs={CONTROL: 500.0})
    gain = lqr_controller(
        design, [CONTROL], bryson=bryson, sample_rate=1 / DT, state_map=state_map(pb, db)
    )
    limits = Limits(magnitude={CONTROL: 2000.0}, rate={CONTROL: 2e5})
    x0 = tip_deflection_state(pb, TIP)
    plant_f = with_sensor_filters(plant, SENSORS[:2], 30.0)
    design_f = with_sensor_filters(design, SENSORS[:2], 30.0)
    x0_f = np.r_[x0, np.zeros(plant_f.nstates - plant.nstates)]
    return dict(
        vf=vf,
        plant=plant,
        lqr=gain,
        limits=limits,
        x0=x0,
        bryson=bryson,
        plant_f=plant_f,
        design_f=design_f,
        x0_f=x0_f,
    )
