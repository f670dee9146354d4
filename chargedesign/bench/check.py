"""What the forward check and the continuous-body quadrature cost.

Four tables, each against a baseline measured in the same run:

1. Throughput of the rotated-body check (element-orientation pairs per second): the
   vectorised kernel (:func:`chargedesign.checker.evaluate_rotated`) and the whole
   :func:`chargedesign.checker.check_design` against a straightforward per-orientation Python
   loop (:func:`naive_sums`: rotate, call :class:`chargedesign.fields.AxisymmetricField`
   ``potential``/``gradient``/``hessian`` in space axes, sum with numpy, rotate back). The
   largest relative difference between the two is reported too (they share no field code).
2. Cost of the accurate path (:func:`chargedesign.checker.evaluate_accurate` in double-double
   and in ``np.longdouble``) against the double kernel.
3. Accuracy against cancellation: a body plus finite-difference stencils of huge charges whose
   contributions cancel exactly, so its true mu and V are those of the body without them;
   error of the double kernel, of exactly summed (``math.fsum``) double contributions, of
   longdouble and of double-double, against that truth, with the check's stated floor.
4. Quadrature convergence on smooth non-polynomial integrands with closed-form integrals:
   relative error against nodes and time, the time as a ratio to the degree-1 rule.

Run ``python -m chargedesign.bench.check [--quick] [--plot PNG]`` (or ``chargedesign bench
--only check``); ``--plot`` writes the convergence figure used in docs/check.md.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from chargedesign.bench.common import UNIT_SCALE, BenchTable, best_time
from chargedesign.body import Design
from chargedesign.checker import (
    EPS,
    FIELD_NAMES,
    check_design,
    collect_elements,
    contribution_sizes,
    evaluate_accurate,
    evaluate_rotated,
    rotation_matrices,
    rounding_floor,
    sample_orientations,
)
from chargedesign.fields import AxisymmetricField
from chargedesign.files import atomic_path
from chargedesign.quadrature import ContinuousBody, Density, geometric_rule

#: fields of the benchmark design (the default scene's magnetic field, a degree-4 electric
#: field, uniform gravity)
BENCH_FIELDS = {"magnetic": (1.0, 1.0), "electric": (0.3, 0.5, -0.28, 0.6), "gravity": (9.81,)}


def bench_design(n_charges: int, n_masses: int, n_dipoles: int, seed: int = 0) -> Design:
    """A random design (elements in the unit ball) for timing; it realises nothing."""
    rng = np.random.default_rng(seed)

    def ball(n: int) -> np.ndarray:
        v = rng.standard_normal((n, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        return v * rng.uniform(0.0, 1.0, (n, 1)) ** (1.0 / 3.0)

    return Design(
        parameters=UNIT_SCALE,
        fields=dict(BENCH_FIELDS),
        charge_positions=ball(n_charges),
        charge_values=rng.standard_normal(n_charges),
        mass_positions=ball(n_masses),
        mass_values=rng.uniform(0.1, 1.0, n_masses),
        dipole_positions=ball(n_dipoles),
        dipole_moments=rng.standard_normal((n_dipoles, 3)),
    )


def naive_sums(design: Design, R: np.ndarray, omegas: np.ndarray) -> dict[str, np.ndarray]:
    """The baseline: one orientation at a time, fields from chargedesign.fields (space axes).

    Parameters
    ----------
    design : Design
        Point elements only.
    R : ndarray, shape (m, 3, 3)
        Body-to-space rotations.
    omegas : ndarray, shape (m, 3)
        Angular velocities in body axes, rad/s.

    Returns
    -------
    dict with ``mu``, ``gyro``, ``torque`` (m, 3) in body axes and ``energy`` (m,), SI units.
    """
    f = {k: AxisymmetricField(design.field(k)) for k in FIELD_NAMES}
    m = len(R)
    out = {
        "mu": np.zeros((m, 3)),
        "gyro": np.zeros((m, 3)),
        "torque": np.zeros((m, 3)),
        "energy": np.zeros(m),
    }
    rq, q = design.charge_positions, design.charge_values
    rm, w = design.mass_positions, design.mass_values
    rd, sig = design.dipole_positions, design.dipole_moments
    for i in range(m):
        Ri = R[i]
        Xq, Xm, Xd, Sd = rq @ Ri.T, rm @ Ri.T, rd @ Ri.T, sig @ Ri.T
        B = -f["magnetic"].gradient(Xq)
        mu = -((q * np.einsum("ij,ij->i", Xq, B))[:, None] * Xq).sum(axis=0)
        v = np.cross(Ri @ omegas[i], Xq)
        gyro = np.cross(Xq, q[:, None] * np.cross(v, B)).sum(axis=0)
        energy = q @ f["electric"].potential(Xq) + w @ f["gravity"].potential(Xm)
        torque = -np.cross(Xq, q[:, None] * f["electric"].gradient(Xq)).sum(axis=0)
        torque -= np.cross(Xm, w[:, None] * f["gravity"].gradient(Xm)).sum(axis=0)
        Bd = -f["magnetic"].gradient(Xd)
        force = -np.einsum("nij,nj->ni", f["magnetic"].hessian(Xd), Sd)
        energy -= np.einsum("ij,ij->", Sd, Bd)
        torque += (np.cross(Sd, Bd) + np.cross(Xd, force)).sum(axis=0)
        out["mu"][i] = Ri.T @ mu
        out["gyro"][i] = Ri.T @ gyro
        out["torque"][i] = Ri.T @ torque
        out["energy"][i] = energy
    return out


def _max_rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def _bench_inputs(nq: int, nm: int, nd: int, m: int) -> tuple[Any, ...]:
    """The benchmark body and, for ``m`` orientations, everything the kernels take:
    ``(design, gammas, rotations, omegas, elements, fields)``."""
    design = bench_design(nq, nm, nd)
    gammas = sample_orientations(m)
    rng = np.random.default_rng(1)
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((m, 3))
    elements, _ = collect_elements(design)
    fields = {k: design.field(k) for k in FIELD_NAMES}
    return design, gammas, R, omegas, elements, fields


def _throughput_row(nq: int, nm: int, nd: int, m: int, repeat: int) -> list[Any]:
    """One row of the throughput table (see :func:`throughput_table`)."""
    design, _gammas, R, omegas, elements, fields = _bench_inputs(nq, nm, nd, m)
    pairs = m * (nq + nm + nd)
    t_kernel, sums = best_time(lambda: evaluate_rotated(elements, fields, R, omegas), repeat)
    t_check, _ = best_time(lambda: check_design(design, n_orientations=m), repeat)
    m_loop = min(m, 200)
    t_loop, ref = best_time(lambda: naive_sums(design, R[:m_loop], omegas[:m_loop]), 1)
    diff = max(
        _max_rel(sums.mu[:m_loop], ref["mu"]) if nq else 0.0,
        _max_rel(sums.gyro[:m_loop], ref["gyro"]) if nq else 0.0,
        _max_rel(sum(sums.torque.values())[:m_loop], ref["torque"]),
        _max_rel(sum(sums.energy.values())[:m_loop], ref["energy"]),
    )
    loop_rate = m_loop * (nq + nm + nd) / t_loop
    kernel_rate = pairs / t_kernel
    return [
        f"{nq} / {nm} / {nd}",
        kernel_rate,
        pairs / t_check,
        loop_rate,
        kernel_rate / loop_rate,
        diff,
    ]


def throughput_table(quick: bool = False) -> BenchTable:
    """Pairs per second of the vectorised check against the per-orientation loop."""
    if quick:
        cases = [(100, 6, 10), (1000, 6, 10)]
    else:
        cases = [(100, 6, 10), (1000, 20, 10), (10000, 100, 20), (0, 0, 1000)]
    m = 100 if quick else 2000
    table = BenchTable(
        title=f"check: rotated-body evaluation, {m} orientations",
        columns=[
            "charges / masses / dipoles",
            "kernel pairs per s",
            "check_design pairs per s",
            "loop pairs per s",
            "kernel speed-up over loop",
            "max rel diff kernel vs loop",
        ],
    )
    for nq, nm, nd in cases:
        table.rows.append(_throughput_row(nq, nm, nd, m, 2 if quick else 3))
    table.notes += [
        "pair = one element at one orientation with everything the check needs there "
        "(charges: E potential and gradient, B, mu, Lorentz torque; masses: gravity potential "
        "and gradient; dipoles: B and its Hessian); best of several runs.",
        "check_design adds the theorem's evaluators, the comparisons and the per-effect "
        "polynomial fits; the loop baseline (chargedesign.fields, one orientation at a time) "
        "runs on the first 200 orientations.",
        "2-core machine shared with other work: absolute rates vary by tens of percent.",
    ]
    return table


# ------------------------------------------------------------- accurate path: cost
def _accurate_cost_row(nq: int, nm: int, nd: int, m: int, repeat: int) -> list[Any]:
    """One row of :func:`accurate_cost_table`."""
    design, gammas, R, omegas, elements, fields = _bench_inputs(nq, nm, nd, m)
    pairs = m * (nq + nm + nd)
    t_double, _ = best_time(lambda: evaluate_rotated(elements, fields, R, omegas), repeat)
    t_dd, _ = best_time(lambda: evaluate_accurate(elements, fields, gammas, omegas), repeat)
    t_ld, _ = best_time(
        lambda: evaluate_accurate(elements, fields, gammas, omegas, precision="longdouble"),
        repeat,
    )
    t_check, _ = best_time(
        lambda: check_design(design, n_orientations=m, precision="double-double"), repeat
    )
    return [
        f"{nq} / {nm} / {nd}",
        pairs / t_double,
        pairs / t_dd,
        pairs / t_ld,
        pairs / t_check,
        t_dd / t_double,
    ]


def accurate_cost_table(quick: bool = False) -> BenchTable:
    """Pairs per second of the extended-precision sums against the double kernel."""
    cases = [(100, 6, 10)] if quick else [(100, 6, 10), (1000, 20, 10), (0, 0, 1000)]
    m = 100 if quick else 1000
    repeat = 2 if quick else 3
    table = BenchTable(
        title=f"check: cost of the accurate path, {m} orientations",
        columns=[
            "charges / masses / dipoles",
            "double kernel pairs per s",
            "double-double pairs per s",
            "longdouble pairs per s",
            "check_design (double-double) pairs per s",
            "double-double time / double time",
        ],
    )
    for nq, nm, nd in cases:
        table.rows.append(_accurate_cost_row(nq, nm, nd, m, repeat))
    table.notes += [
        "check_design uses double-double only when a claimed quantity's double rounding floor "
        "exceeds 1 % of the tolerance (precision='auto'); the benchmark designs claim nothing, "
        "so table 1's check_design column is the double path.",
        "check_design (double-double) runs the double kernel too (the gross sizes and the "
        "effects' route agreement), then the accurate sums.",
    ]
    return table


# --------------------------------------------------------- accurate path: accuracy
STENCIL = np.array([1.0, -5.0, 10.0, -10.0, 5.0, -1.0])  # fifth difference


def stencil_points(weight: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Three stencils of six collinear points ``p + j h`` with weights ``weight (-1)^j C(5, j)``.

    ``p`` and ``h`` are multiples of 2^-10 and the weights exact doubles, so any polynomial of
    degree <= 4 summed over a stencil is exactly zero. Returns points (18, 3) and weights (18,).
    """
    rng = np.random.default_rng(seed)
    points, values = [], []
    for _ in range(3):
        p = np.round(rng.uniform(-0.5, 0.5, 3) * 1024) / 1024
        h = np.round(rng.uniform(-0.08, 0.08, 3) * 1024) / 1024
        points += [p + j * h for j in range(6)]
        values += list(weight * STENCIL)
    return np.array(points), np.array(values)


def stencil_body(base: Design, weight: float, seed: int = 0) -> Design:
    """``base`` plus three stencils of charges ``weight (-1)^j C(5, j)`` at ``p + j h``.

    The fifth difference of a polynomial of degree <= 4 is zero, and every integrand of the
    benchmark fields is one, so the stencils add exactly nothing to mu, V or the torques
    (positions on a 2^-10 grid and the weights are exact doubles) while their contributions
    are ``weight`` times larger than the base body's.
    """
    points, values = stencil_points(weight, seed)
    return Design(
        parameters=base.parameters,
        fields=dict(base.fields),
        charge_positions=np.concatenate([base.charge_positions, points]),
        charge_values=np.concatenate([base.charge_values, values]),
        mass_positions=base.mass_positions,
        mass_values=base.mass_values,
        dipole_positions=base.dipole_positions,
        dipole_moments=base.dipole_moments,
    )


def _fsum_of_double_contributions(
    design: Design, gammas: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """mu and the energy from per-element contributions evaluated in double (body axes,
    chargedesign.fields) and summed exactly with math.fsum: exact summation alone."""
    magnetic = AxisymmetricField(design.field("magnetic"))
    parts_e = [
        (
            design.charge_positions,
            design.charge_values,
            AxisymmetricField(design.field("electric")),
        ),
        (design.mass_positions, design.mass_values, AxisymmetricField(design.field("gravity"))),
    ]
    r, q = design.charge_positions, design.charge_values
    B = -magnetic.gradient_body(r, gammas)  # (m, n, 3)
    mu_terms = -(q * np.einsum("mnc,nc->mn", B, r))[:, :, None] * r[None]
    energy_terms = [w * f.potential_body(p, gammas) for p, w, f in parts_e if len(w)]
    if len(design.dipole_moments):
        Bd = -magnetic.gradient_body(design.dipole_positions, gammas)
        energy_terms.append(-np.einsum("mnc,nc->mn", Bd, design.dipole_moments))
    energy_all = np.concatenate(energy_terms, axis=1)
    mu = np.array([[math.fsum(mu_terms[i, :, c]) for c in range(3)] for i in range(len(gammas))])
    energy = np.array([math.fsum(row) for row in energy_all])
    return mu, energy


def accuracy_table(quick: bool = False) -> BenchTable:
    """Relative error of mu and V against cancellation, per arithmetic."""
    base = bench_design(40, 6, 8, seed=2)
    weights = [1.0, 2.0**20, 2.0**40] if quick else [1.0, 2.0**10, 2.0**20, 2.0**30, 2.0**40]
    m = 50 if quick else 300
    gammas = sample_orientations(m, seed=3)
    rng = np.random.default_rng(4)
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((m, 3))
    fields = {k: base.field(k) for k in FIELD_NAMES}
    truth = evaluate_accurate(collect_elements(base)[0], fields, gammas, omegas)
    table = BenchTable(
        title="check: accuracy against cancellation (mu, V; stencils of huge charges)",
        columns=[
            "stencil weight",
            "quantity",
            "cancellation",
            "double kernel",
            "fsum of double contributions",
            "longdouble",
            "double-double",
            "stated double floor",
        ],
        plot={
            "x": "cancellation",
            "y": ["double kernel", "fsum of double contributions", "longdouble", "double-double"],
            "group": "quantity",
            "logx": True,
            "logy": True,
        },
    )
    for weight in weights:
        body = stencil_body(base, weight)
        elements, _ = collect_elements(body)
        sizes = contribution_sizes(elements, fields)
        fast = evaluate_rotated(elements, fields, R, omegas)
        ld = evaluate_accurate(elements, fields, gammas, omegas, precision="longdouble")
        dd = evaluate_accurate(elements, fields, gammas, omegas)
        fs_mu, fs_energy = _fsum_of_double_contributions(body, gammas)
        energy = np.sum(list(fast.energy.values()), axis=0)
        routes = {
            "mu": (truth.mu, [fast.mu, fs_mu, ld.mu, dd.mu]),
            "V": (
                truth.energy_centered,
                [
                    energy - energy.mean(),
                    fs_energy - fs_energy.mean(),
                    ld.energy_centered,
                    dd.energy_centered,
                ],
            ),
        }
        for name, (want, got) in routes.items():
            scale = (
                float(np.abs(want).max())
                if want.ndim == 1
                else float(np.linalg.norm(want, axis=1).max())
            )
            errors = [
                float((np.abs(g - want) if g.ndim == 1 else np.linalg.norm(g - want, axis=1)).max())
                / scale
                for g in got
            ]
            cancellation = sizes[name] / scale
            table.rows.append(
                [
                    f"2^{int(math.log2(weight))}",
                    name,
                    cancellation,
                    *errors,
                    rounding_floor(cancellation, EPS),
                ]
            )
    table.notes += [
        "truth: the base body's sums in double-double (the stencils add exactly zero); "
        "errors relative to max |mu| and to V's spread over the orientations.",
        "fsum of double contributions: each element's contribution rounded to double "
        "(chargedesign.fields, body axes), then summed exactly; it shows that the rounding of "
        "the contributions, not of the summation, sets the floor.",
        "stated double floor: ROUNDING_FACTOR * EPS * (cancellation + 1), what check_design "
        "reports as double_rounding_floor.",
    ]
    return table


# ------------------------------------------------------------------ quadrature study
def _integrands() -> list[tuple[str, ContinuousBody, Callable[[np.ndarray], np.ndarray], float]]:
    """(label, body, integrand f(points), exact integral of f over the body)."""
    from scipy.special import iv

    one = Density("uniform", 1.0)
    origin = np.zeros(3)
    p = np.array([0.0, 0.0, 1.5])

    def exp_x(x: np.ndarray) -> np.ndarray:
        return np.exp(x[:, 0])

    def newton(x: np.ndarray) -> np.ndarray:
        return 1.0 / np.linalg.norm(x - p, axis=1)

    def exp_sum(x: np.ndarray) -> np.ndarray:
        return np.exp(x.sum(axis=1))

    ball = ContinuousBody("mass", "ball", origin, one, radius=1.0)
    shell = ContinuousBody("mass", "shell", origin, one, radius=1.0)
    cylinder = ContinuousBody("mass", "cylinder", origin, one, radius=1.0, height=2.0)
    box = ContinuousBody("mass", "box", origin, one, half_size=np.ones(3))
    return [
        ("ball: exp(x)", ball, exp_x, 4.0 * math.pi / math.e),
        ("ball: 1/|x - p|, |p| = 1.5", ball, newton, 4.0 * math.pi / 3.0 / 1.5),
        ("shell: 1/|x - p|, |p| = 1.5", shell, newton, 4.0 * math.pi / 1.5),
        ("cylinder: exp(x)", cylinder, exp_x, 2.0 * math.pi * float(iv(1, 1.0)) * 2.0),
        ("box: exp(x + y + z)", box, exp_sum, (2.0 * math.sinh(1.0)) ** 3),
    ]


def quadrature_table(quick: bool = False) -> BenchTable:
    """Relative error against nodes and time for smooth non-polynomial integrands."""
    orders = [1, 5, 9] if quick else [1, 3, 5, 7, 9, 13, 17, 25]
    repeat = 2 if quick else 5
    table = BenchTable(
        title="quadrature: error against nodes and time (smooth non-polynomial integrands)",
        columns=["integrand", "degree", "nodes", "rel error", "time us", "time / degree-1 time"],
        plot={
            "x": "nodes",
            "y": ["rel error"],
            "y2": ["time us"],
            "group": "integrand",
            "logx": True,
            "logy": True,
            "logy2": True,
        },
    )
    for label, body, f, exact in _integrands():
        base = None
        for order in orders:

            def integrate(
                b: ContinuousBody = body, d: int = order, g: Callable[..., Any] = f
            ) -> float:
                pts, w = geometric_rule(b, d)
                return float(w @ g(pts))

            t, value = best_time(integrate, repeat)
            base = t if base is None else base
            nodes = len(geometric_rule(body, order)[1])
            table.rows.append(
                [label, order, nodes, abs(value - exact) / abs(exact), t * 1e6, t / base]
            )
    table.notes += [
        "integral of f over the body with unit density; exact values in closed form "
        "(4 pi / e; Newton's theorem M / |p| and 4 pi a^2 / |p|; 2 pi I_1(1) h; (2 sinh 1)^3).",
        "time = building the rule and evaluating f at its nodes; errors at 1e-16 are rounding.",
    ]
    return table


def plot_quadrature_convergence(table: BenchTable, path: str | None = None) -> Any:
    """Error against nodes (left) and time (right) per integrand; returns the figure.

    Parameters
    ----------
    table : BenchTable
        The quadrature table.
    path : str, optional
        Write a PNG there (atomically).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows_by: dict[str, list[list[Any]]] = {}
    for row in table.rows:
        rows_by.setdefault(row[0], []).append(row)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    fig.suptitle("Quadrature of continuous bodies: convergence beyond the exact degree")
    for label, rows in rows_by.items():
        err = [max(r[3], 1e-17) for r in rows]
        axes[0].loglog([r[2] for r in rows], err, "o-", label=label)
        axes[1].semilogy([r[4] for r in rows], err, "o-", label=label)
    axes[0].set_xlabel("nodes")
    axes[1].set_xlabel("time (us): building the rule + evaluating the integrand")
    for one in axes:
        one.set_ylabel("relative error")
        one.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    if path is not None:
        fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=110)
        plt.close(fig)
    return fig


def run(quick: bool = False) -> list[BenchTable]:
    """All four tables (``quick``: small sizes, a few seconds)."""
    return [
        throughput_table(quick),
        accurate_cost_table(quick),
        accuracy_table(quick),
        quadrature_table(quick),
    ]


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m chargedesign.bench.check")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--plot", metavar="PNG", help="write the convergence figure")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    tables = run(args.quick)
    for table in tables:
        sys.stdout.write(table.to_markdown() + "\n")
    if args.plot:
        plot_quadrature_convergence(tables[-1], args.plot)
    sys.stdout.write(f"(ran in {time.perf_counter() - t0:.1f} s)\n")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
