"""The Monte Carlo of perturbed bodies: their relative errors (exact and first order), their
I4 drift against the error level beside the linear-response prediction, and its plot.

Part of :mod:`chargedesign.tolerancing` (see its docstring for the method).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.formatting import AGREEMENT, ERROR, PLAIN, fmt
from chargedesign.limits import MAX_TOLERANCE_LEVELS as MAX_LEVELS
from chargedesign.results import Result, json_ready
from chargedesign.scene.keys import KEY
from chargedesign.sensitivity import (
    DEFAULT_ORIENTATIONS,
    QUANTITIES,
    analysed_elements,
    batched_quantities,
    design_fields,
    jacobians,
    orientations,
    quantities,
    quantity_scales,
    references,
    with_arrays,
    with_masses,
)
from chargedesign.tolerancing.common import (
    DEFAULT_LEVELS,
    DEFAULT_RTOL,
    DEFAULT_T_END,
    DEFAULT_TARGET,
    quantile_summary,
    sample_count,
)
from chargedesign.tolerancing.element_tolerances import (
    ToleranceReport,
    relative_errors,
    tolerance_report,
)
from chargedesign.tolerancing.ensemble import linear_drift, simulate_ensemble
from chargedesign.tolerancing.error_model import (
    ErrorModel,
    element_rows,
    linear_errors,
    perturbed_arrays,
    standard_deviations,
)
from chargedesign.tolerancing.material_properties import MaterialErrors
from chargedesign.validation import as_finite_float


@dataclass(repr=False)
class MonteCarloResult(Result):
    """The Monte Carlo of perturbed bodies beside the linear-response prediction.

    Attributes
    ----------
    model : ErrorModel
        The errors at level 1 (one standard deviation each).
    errors : dict
        Per quantity: ``monte_carlo`` and ``linear`` relative errors, arrays (n,) at level 1
        (exact for each perturbed body; first order from the exact derivatives), and
        ``linear_rms`` (the predicted rms, no sampling).
    levels : ndarray
        Scale factors of the error model for the drift curve.
    drift_mc, drift_linear : ndarray, shape (levels, n_drift)
        Max over time of each perturbed body's I4 relative drift, simulated and predicted.
    drift_times, drift_median_over_time : ndarray
        The level-1 bodies' median drift against time.
    nominal_drift : float
        The unperturbed body's own drift (the integration's floor).
    """

    model: ErrorModel
    n: int
    errors: dict[str, dict[str, Any]]
    levels: np.ndarray
    drift_mc: np.ndarray
    drift_linear: np.ndarray
    drift_times: np.ndarray
    drift_median_over_time: np.ndarray
    drift_p90_over_time: np.ndarray
    nominal_drift: float
    t_end: float
    seconds: dict[str, float] = field(default_factory=dict)
    report: ToleranceReport | None = None

    def to_dict(self) -> dict[str, Any]:
        errs = {
            q: {
                "monte_carlo": quantile_summary(v["monte_carlo"]),
                "linear": quantile_summary(v["linear"]),
                "linear_rms": v["linear_rms"],
            }
            for q, v in self.errors.items()
        }
        drift = []
        for i, level in enumerate(self.levels):
            drift.append(
                {
                    "level": float(level),
                    "position_m": self.model.position.value * float(level)
                    if not self.model.position.relative
                    else None,
                    "monte_carlo": quantile_summary(self.drift_mc[i]),
                    "linear": quantile_summary(self.drift_linear[i]),
                }
            )
        out: dict[str, Any] = {
            "format": "chargedesign.tolerance-mc/1",
            "errors_model": self.model.to_dict(),
            "samples": self.n,
            KEY.t_end: self.t_end,
            "rel_errors": errs,
            "I4_drift": drift,
            "I4_drift_nominal": self.nominal_drift,
            "seconds": dict(self.seconds),
        }
        if self.report is not None:
            out["sensitivity"] = self.report.to_dict()
        return json_ready(out)

    def _summary(self) -> dict[str, Any]:
        return {
            "samples": self.n,
            "levels": len(self.levels),
            KEY.t_end: self.t_end,
            **{
                f"{q}_rel_err_p90": float(np.percentile(v["monte_carlo"], 90))
                for q, v in self.errors.items()
            },
            # at the error level closest to the one given (level 1); None when not simulated
            "I4_drift_median": float(
                np.median(self.drift_mc[int(np.argmin(np.abs(self.levels - 1.0)))])
            )
            if self.drift_mc.size
            else None,
        }

    def _text(self) -> str:
        lines = []
        if self.report is not None:
            lines += [str(self.report), ""]
        lines.append(
            f"Monte Carlo: {self.n} perturbed bodies (errors at one standard deviation: "
            + ", ".join(f"{k} {v}" for k, v in self.model.to_dict().items())
            + ")"
        )
        lines.append(f"{'quantity':<9} {'MC median':>10} {'MC p90':>10} {'linear p90':>10}")
        for q, v in self.errors.items():
            mc, lin = quantile_summary(v["monte_carlo"]), quantile_summary(v["linear"])
            lines.append(
                f"{q:<9} {fmt(mc['median'], ERROR):>10} {fmt(mc['p90'], ERROR):>10}"
                f" {fmt(lin['p90'], ERROR):>10}"
            )
        lines.append("")
        if not self.drift_mc.size:  # --no-simulate: no drift was computed, say so (no nan)
            lines.append("I4 drift: not simulated (--no-simulate)")
            return "\n".join(lines)
        lines.append(
            f"I4 relative drift to t = {fmt(self.t_end, PLAIN)} s (median over bodies; nominal body"
            " "
            f"{fmt(self.nominal_drift, AGREEMENT)}):"
        )
        lines.append(f"{'level':>8} {'Monte Carlo':>12} {'linear':>12}")
        for i, level in enumerate(self.levels):
            lines.append(
                f"{fmt(level):>8} {fmt(np.median(self.drift_mc[i]), ERROR):>12} "
                f"{fmt(np.median(self.drift_linear[i]), ERROR):>12}"
            )
        return "\n".join(lines)


def _designs_from_draws(design: Design, draws: Mapping[str, np.ndarray]) -> list[Design]:
    out = []
    for b in range(len(draws["cv"])):
        d = with_arrays(
            design,
            charge_positions=draws["cp"][b],
            charge_values=draws["cv"][b],
            dipole_positions=draws["dp"][b],
            dipole_moments=draws["dm"][b],
        )
        out.append(with_masses(d, draws["mp"][b], draws["mv"][b]))
    return out


def error_distribution(
    design: Design,
    model: ErrorModel,
    n: int,
    *,
    seed: int = 0,
    n_orientations: int = DEFAULT_ORIENTATIONS,
    tally: Callable[[int], None] | None = None,
) -> dict[str, dict[str, Any]]:
    """Relative errors of ``n`` perturbed bodies: exact (Monte Carlo) and first order
    (``tally(done)`` is told the bodies drawn so far).

    Returns
    -------
    dict
        Per quantity: ``monte_carlo`` (n,), ``linear`` (n,) and ``linear_rms`` (float).
    """
    el = analysed_elements(design)
    gammas = orientations(n_orientations, 0)
    ref = references(design, gammas)
    scales = quantity_scales(design, ref)
    f = design_fields(design)
    jac = jacobians(design, gammas)
    nominal = quantities(el, f, gammas)
    rng = np.random.default_rng(seed)
    mc = {q: [] for q in QUANTITIES}  # type: dict[str, list[np.ndarray]]
    lin = {q: [] for q in QUANTITIES}  # type: dict[str, list[np.ndarray]]
    chunk = max(1, 20000 // max(1, len(gammas)))
    done = 0
    while done < n:
        k = min(chunk, n - done)
        draws = perturbed_arrays(el, model, k, rng)
        exact = batched_quantities(
            draws["cp"], draws["cv"], draws["dp"], draws["dm"], draws["mp"], draws["mv"], f, gammas
        )
        first = linear_errors(jac, el, draws)
        predicted = {
            "mu": nominal["mu"][None] + first["mu"],
            "V": nominal["V"][None] + first["V"][..., 0],
            "inertia": nominal["inertia"][None] + first["inertia"][:, 0].reshape(k, 3, 3),
        }
        for q, v in relative_errors(exact, ref, scales).items():
            mc[q].append(v)
        for q, v in relative_errors(predicted, ref, scales).items():
            lin[q].append(v)
        done += k
        if tally is not None:
            tally(done)
    spos, sval = element_rows(el, standard_deviations(el, model))  # (N, 3) each
    out: dict[str, dict[str, Any]] = {}
    for q in QUANTITIES:
        var = np.einsum("nmdc,nc->md", jac.position[q] ** 2, spos**2) + np.einsum(
            "nmdc,nc->md", jac.value[q] ** 2, sval**2
        )
        if q == "inertia":
            rms = float(np.sqrt(var.max(initial=0.0)))
        else:
            rms = float(np.sqrt(var.sum(axis=1).max(initial=0.0)))
        out[q] = {
            "monte_carlo": np.concatenate(mc[q]),
            "linear": np.concatenate(lin[q]),
            "linear_rms": rms / scales[q],
        }
    return out


def monte_carlo(
    design: Design,
    model: ErrorModel,
    *,
    samples: int = 200,
    drift_samples: int | None = None,
    t_end: float = DEFAULT_T_END,
    levels: Sequence[float] = DEFAULT_LEVELS,
    seed: int = 0,
    rtol: float = DEFAULT_RTOL,
    target: float = DEFAULT_TARGET,
    material_errors: MaterialErrors | None = None,
    tally: Callable[[int, int], None] | None = None,
) -> MonteCarloResult:
    """Monte Carlo of perturbed bodies: error distributions, I4 drift, linear prediction.

    Parameters
    ----------
    design : Design
    model : ErrorModel
        The manufacturing errors (one standard deviation each) at level 1.
    samples : int
        Perturbed bodies for the error distributions (1 .. MAX_SAMPLES).
    drift_samples : int, optional
        Perturbed bodies per level for the I4 drift (default ``samples``; 0: no simulation).
    t_end : float
        Duration of the simulations, s.
    levels : sequence of float
        Scale factors of the error model for the drift-against-tolerance curve (positive).
    seed : int
        Seed of the draws.
    rtol : float
        Integration tolerance of the ensemble.
    target : float
        Target of the sensitivity report included.
    material_errors : MaterialErrors, optional
        The materials' property errors, analysed in the report included.
    tally : callable, optional
        ``tally(done, total)``: the bodies done, of ``samples`` drawn for the distributions
        and then the nominal and every perturbed body simulated (one batch, counted by the
        time integrated).

    Returns
    -------
    MonteCarloResult
    """
    samples = sample_count(samples, "samples", 1)
    n_drift = samples if drift_samples is None else sample_count(drift_samples, "drift_samples", 0)
    t_end = as_finite_float(t_end, KEY.t_end, positive=True)
    lv = np.array([as_finite_float(x, "levels", positive=True) for x in levels], dtype=float)
    # the command line checks --levels and asks for a simulation only with an error given
    if not 1 <= len(lv) <= MAX_LEVELS:
        raise ValueError(f"levels: expected 1 to {MAX_LEVELS} scale factors, got {list(levels)}")
    if model.is_zero:
        raise ValueError("model: expected at least one error (position, charge, dipole, mass)")
    seconds: dict[str, float] = {}
    total = samples + (1 + len(lv) * n_drift if n_drift else 0)
    count = (lambda done: None) if tally is None else (lambda done: tally(done, total))
    count(0)
    t0 = time.perf_counter()
    report = tolerance_report(design, target, material_errors=material_errors)
    seconds["sensitivity"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    errors = error_distribution(design, model, samples, seed=seed, tally=count)
    seconds["errors"] = time.perf_counter() - t0
    el = analysed_elements(design)
    rng = np.random.default_rng([seed, 1])
    drift_mc = np.zeros((len(lv), n_drift))
    drift_lin = np.zeros((len(lv), n_drift))
    times = np.zeros(0)
    med = p90 = np.zeros(0)
    nominal_drift = 0.0
    if n_drift:
        bodies: list[Design] = [design]
        for level in lv:
            draws = perturbed_arrays(el, model.scaled(float(level)), n_drift, rng)
            bodies += _designs_from_draws(design, draws)
        t0 = time.perf_counter()
        run = simulate_ensemble(
            bodies,
            t_end=t_end,
            rtol=rtol,
            atol=rtol,
            progress=lambda f: count(samples + int(f * len(bodies))),
        )
        seconds["simulation"] = time.perf_counter() - t0
        nominal_drift = float(run.drift[0].max())
        per_body = run.drift[1:].max(axis=1).reshape(len(lv), n_drift)
        drift_mc = per_body
        one = int(np.argmin(np.abs(np.log(lv))))
        block = run.drift[1 + one * n_drift : 1 + (one + 1) * n_drift]
        times = run.times
        med = np.median(block, axis=0)
        p90 = np.quantile(block, 0.9, axis=0)
        t0 = time.perf_counter()
        drift_lin = linear_drift(design, bodies[1:], t_end).reshape(len(lv), n_drift)
        seconds["linear_drift"] = time.perf_counter() - t0
    return MonteCarloResult(
        model=model,
        n=samples,
        errors=errors,
        levels=lv,
        drift_mc=drift_mc,
        drift_linear=drift_lin,
        drift_times=times,
        drift_median_over_time=med,
        drift_p90_over_time=p90,
        nominal_drift=nominal_drift,
        t_end=t_end,
        seconds=seconds,
        report=report,
    )


def plot_drift(result: MonteCarloResult, ax: Any = None) -> Any:
    """Log-log plot of the I4 drift against the tolerance: Monte Carlo and linear response.

    Parameters
    ----------
    result : MonteCarloResult
    ax : matplotlib Axes, optional
        Drawn into; a new figure otherwise.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    pos = result.model.position
    if pos.value > 0.0 and not pos.relative:
        x = result.levels * pos.value
        ax.set_xlabel("position error (m, one standard deviation)")
    else:
        x = result.levels
        ax.set_xlabel(
            "error scale (1 = "
            + ", ".join(
                f"{k} {v}" for k, v in result.model.to_dict().items() if not v.startswith("0")
            )
            + ")"
        )
    mc_med = np.median(result.drift_mc, axis=1)
    mc_p90 = np.quantile(result.drift_mc, 0.9, axis=1)
    lin_med = np.median(result.drift_linear, axis=1)
    ax.loglog(x, mc_med, "o-", label="Monte Carlo (median)")
    ax.fill_between(x, mc_med, mc_p90, alpha=0.2, label="Monte Carlo (median..p90)")
    ax.loglog(x, lin_med, "s--", label="linear response (median)")
    if result.nominal_drift > 0.0:
        ax.axhline(result.nominal_drift, color="gray", lw=0.8, ls=":", label="nominal body")
    ax.set_ylabel(f"I4 relative drift to t = {fmt(result.t_end, PLAIN)} s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return ax
