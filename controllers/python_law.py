"""The law of ``python.toml``: the hinge moment from the three tip sensors through a smooth
limiter, ``u = -M tanh(K y / M)``.

``y`` holds ``tip_le_accel`` [m/s^2], ``tip_te_accel`` [m/s^2] and ``tip_twist`` [rad], in the
order of the controller file's ``sensors``; the command is ``aileron_hinge_moment`` [N m],
positive trailing edge down. ``K`` is the static gain of ``gain.toml``; for small signals the
law is that gain, near ``M`` it gives less than the actuator could.
"""

import numpy as np

K = np.array([3.1, 1.8, 4.2e4])  # N m per m/s^2, N m per m/s^2, N m per rad
M = 2000.0  # N m: the limiter's asymptote, the actuator's magnitude limit


def command(t, y):
    """Hinge-moment command [N m] at time ``t`` [s] from the sensors ``y``."""
    return [-M * np.tanh(float(K @ np.asarray(y, dtype=float)) / M)]
