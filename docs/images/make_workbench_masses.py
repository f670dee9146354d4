"""The workbench figure: the Kowalevski and Clebsch mass bodies, and the case's integral
along their element-level motion.

    python docs/images/make_workbench_masses.py docs/images/workbench_masses.png
"""

import sys

import matplotlib
import numpy as np
import sympy as sp

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from scipy.integrate import solve_ivp

from chargedesign.candidates import ball_points
from chargedesign.designer.case_masses import mass_conditions
from chargedesign.designer.pipeline import design_body
from chargedesign.model.case import GAMMA, OMEGA
from chargedesign.model.catalogue import catalogue_case
from chargedesign.params import Parameters
from chargedesign.physical.holder import point_inertia


class MassBody:
    """A case's masses in gravity, designed by the one design program."""

    def __init__(self, case):
        params = Parameters(C=float(case.inertia[2]))
        design = design_body(params, mass_conditions(case), ball_points(1.0, 0.25), forward=False)
        body = design.design
        self.positions, self.masses = body.mass_positions, body.mass_values
        self.gravity = body.fields["gravity"]


fig = plt.figure(figsize=(12, 4))
drift_ax = fig.add_subplot(1, 3, 3)
for k, name in enumerate(["kowalevski", "clebsch"]):
    case = catalogue_case(name)
    body = MassBody(case)
    ax = fig.add_subplot(1, 3, k + 1, projection="3d")
    x = body.positions
    ax.scatter(
        x[:, 0],
        x[:, 1],
        x[:, 2],
        s=400 * body.masses / body.masses.max(),
        c="tab:blue",
        depthshade=False,
    )
    centre = body.masses @ x / body.masses.sum()
    ax.scatter(*centre, marker="x", s=80, c="tab:red")
    ax.scatter(0, 0, 0, marker="+", s=80, c="k")
    for axis, colour in zip(np.eye(3), "rgb"):
        ax.plot(*np.stack([-axis, axis]).T, c=colour, lw=0.6)
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_zlim(-1, 1)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    moments = np.diag(point_inertia(x, body.masses))
    legendre = ", ".join(format(v, ".4g") for v in body.gravity)
    ax.set_title(
        f"{name}: {len(body.masses)} masses, {body.masses.sum():.3g} kg\n"
        f"I = diag({moments[0]:.3g}, {moments[1]:.3g}, {moments[2]:.3g}) kg m^2, "
        f"gravity legendre [{legendre}]",
        fontsize=8,
    )
    f = np.zeros(2)
    f[: len(body.gravity)] = body.gravity
    Im = point_inertia(x, body.masses)

    def rhs(_, y):
        w, g = y[:3], y[3:]
        grad = (body.masses * (f[0] + 3 * f[1] * (x @ g))) @ x
        return np.concatenate(
            [np.linalg.solve(Im, np.cross(g, grad) - np.cross(w, Im @ w)), np.cross(g, w)]
        )

    run = solve_ivp(
        rhs,
        (0, 20),
        [0.3, -0.2, 0.5, 0.6, 0, 0.8],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        dense_output=True,
    )
    F = sp.lambdify([*OMEGA, *GAMMA], case.integral)
    ts = np.linspace(0, 20, 401)
    v = np.array([F(*run.sol(t)) for t in ts])
    drift_ax.semilogy(ts[1:], np.abs(v[1:] - v[0]) / abs(v[0]) + 1e-17, label=name)
drift_ax.set_xlabel("t (s)")
drift_ax.set_ylabel("|F(t) - F(0)| / |F(0)|")
drift_ax.set_title(
    "the case's own integral along the element-level motion\n(DOP853, rtol 1e-12)", fontsize=8
)
drift_ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[1], dpi=110)
print("wrote", sys.argv[1])
