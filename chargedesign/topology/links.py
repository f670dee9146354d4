"""The diagram tied to the Poincare atlas and the FLI map at one energy.

At an energy h the vertical line ``h = const`` of the diagram crosses the critical curves at
the critical values of k. :func:`linked_pictures` draws, side by side: the diagram with that
line; the Poincare atlas on ``I3 = 0`` (:func:`~chargedesign.simulation.chaos.poincare_atlas`)
with each orbit coloured by its value of I4 and the orbits started on the critical periodic
motions (from the diagram's states) marked; the FLI map on ``I3 = 0``
(:func:`~chargedesign.simulation.chaos.fli_map`) at 64 x 48 by default. Needs heyoka.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.formatting import CELL, PLAIN, PRECISE, fmt
from chargedesign.results import Result
from chargedesign.simulation.chaos import (
    FLIMap,
    PoincareAtlas,
    fli_map,
    poincare_atlas,
    section_points,
)
from chargedesign.simulation.system import Body, RigidBodySystem
from chargedesign.topology.chambers import seven_state
from chargedesign.topology.compute import crossing_segments
from chargedesign.topology.diagram import TYPE_COLOURS, BifurcationDiagram, figure_html
from chargedesign.topology.equations import MomentumMap


@dataclass(frozen=True)
class CriticalMotion:
    """Where the line h = const crosses a branch: the value k, the type, a state (SI)."""

    k: float
    branch: int
    type: str
    state: np.ndarray


def critical_motions(diagram: BifurcationDiagram, energy: float) -> list[CriticalMotion]:
    """The crossings of the line ``h = energy`` with the branches, with a state of each
    (interpolated between the two neighbouring rows of the branch, gamma renormalised)."""
    out = []
    for k, index, i, w in crossing_segments(diagram.branches, energy):
        branch = diagram.branches[index]
        # the state on the crossing's own segment (a branch may cross the line more than once)
        state = branch.states[i] + w * (branch.states[i + 1] - branch.states[i])
        state[3:] /= np.linalg.norm(state[3:])
        kind = branch.types[i] if w < 0.5 else branch.types[i + 1]
        out.append(CriticalMotion(k, index, kind, state))
    return out


@dataclass(repr=False)
class LinkedPictures(Result):
    """The diagram, the atlas and the FLI map at one energy (see the module docstring)."""

    diagram: BifurcationDiagram
    energy: float
    critical: list[CriticalMotion]
    atlas: PoincareAtlas
    orbit_k: list[float]
    critical_orbits: list[np.ndarray]
    fli: FLIMap

    def to_dict(self) -> dict[str, Any]:
        return {
            "energy": self.energy,
            "critical": [{"k": c.k, "branch": c.branch, "type": c.type} for c in self.critical],
            "atlas_orbits": len(self.orbit_k),
            "orbit_k": list(self.orbit_k),
            "fli_grid": [len(self.fli.phi), len(self.fli.v)],
            "fli_t_end": self.fli.t_end,
        }

    def _text(self) -> str:
        # deliberately 5 digits (no kind has them): nearby critical levels must read apart
        values = ", ".join(f"{c.k:.5g} ({c.type})" for c in self.critical) or "none"
        return (
            f"energy {fmt(self.energy, CELL)} J: critical values of k {values}; atlas of "
            f"{len(self.orbit_k)} orbits; FLI on {len(self.fli.phi)} x {len(self.fli.v)} points\n"
        )

    def _html_picture(self) -> str:
        return figure_html(self.plot(), 900)

    def plot(self) -> Any:
        """Three panels: diagram with the line h = const, atlas on I3 = 0, FLI on I3 = 0."""
        from matplotlib import colormaps
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize
        from matplotlib.figure import Figure

        fig = Figure(figsize=(17, 5.2))
        left, middle, right = fig.subplots(1, 3)
        self.diagram.plot(left)
        left.axvline(self.energy, color="k", lw=0.8, ls="--")
        for c in self.critical:
            left.plot(self.energy, c.k, "o", color=TYPE_COLOURS[c.type], mec="k", ms=6)
        k_all = np.array(self.orbit_k)
        lo, hi = (float(k_all.min()), float(k_all.max())) if len(k_all) else (0.0, 1.0)
        cmap = colormaps["viridis"]
        for pts, k in zip(self.atlas.points[0], self.orbit_k, strict=True):
            if len(pts):
                shade = cmap((k - lo) / (hi - lo) if hi > lo else 0.5)
                middle.plot(np.arctan2(pts[:, 5], pts[:, 4]), pts[:, 3], ".", ms=1.0, color=shade)
        for pts, c in zip(self.critical_orbits, self.critical, strict=True):
            if len(pts):
                middle.plot(
                    np.arctan2(pts[:, 5], pts[:, 4]),
                    pts[:, 3],
                    "o",
                    ms=3.0,
                    color=TYPE_COLOURS[c.type],
                    mec="k",
                    mew=0.3,
                )
        # two lines: on one, the title runs into the diagram's beside it
        middle.set_title(
            f"Poincare section on I3 = 0 at h = {fmt(self.energy, PRECISE)} J\n"
            "(colour: k; large dots: critical orbits)",
            fontsize=9,
        )
        middle.set_xlabel("phi = atan2(gamma2, gamma1) on gamma3 = 0 [rad]")
        middle.set_ylabel("r [1/s]")
        # the colour carries k: its bar, as the FLI panel has one
        shades = ScalarMappable(Normalize(lo, hi if hi > lo else lo + 1.0), cmap)
        fig.colorbar(shades, ax=middle, label="k = I4 of the orbit")
        image = right.pcolormesh(
            self.fli.phi, self.fli.v, self.fli.fli[0], shading="nearest", cmap="magma"
        )
        fig.colorbar(image, ax=right, label=f"FLI at t = {fmt(self.fli.t_end, PLAIN)} s")
        right.set_title(f"FLI on I3 = 0, {len(self.fli.phi)} x {len(self.fli.v)}", fontsize=9)
        right.set_xlabel("phi on gamma3 = 0 [rad]")
        right.set_ylabel("v = gamma3' [1/s]")
        return fig


def linked_pictures(
    diagram: BifurcationDiagram,
    energy: float,
    *,
    orbits: int = 30,
    t_end: float = 300.0,
    fli_grid: tuple[int, int] = (64, 48),
    fli_t_end: float = 20.0,
) -> LinkedPictures:
    """The atlas and the FLI at ``energy`` (J), tied to the diagram (see the module)."""
    lo, hi = diagram.raw.h_range
    if not lo < energy < hi:  # the command refuses --at outside first: a caller's error here
        raise ValueError(
            f"energy: expected a value inside the diagram's range {fmt(lo, CELL)} .."
            f" {fmt(hi, CELL)} J, "
            f"got {fmt(energy, PLAIN)}"
        )
    params = diagram.raw.params
    system = RigidBodySystem(Body(parameters=params), ["theorem"])
    atlas = poincare_atlas(system, energy=energy, orbits=orbits, t_end=t_end)
    F = MomentumMap(params)
    orbit_k = [
        float(F.values(pts[:1, 1:7])[0, 1]) if len(pts) else float("nan") for pts in atlas.points[0]
    ]
    critical = critical_motions(diagram, energy)
    starts = np.array([seven_state(c.state) for c in critical]).reshape(-1, 7)
    critical_orbits = section_points(system, starts, t_end) if len(starts) else []
    fmap = fli_map(
        system,
        energy=energy,
        n_phi=fli_grid[0],
        n_v=fli_grid[1],
        t_end=fli_t_end,
        on_level_only=True,
    )
    return LinkedPictures(diagram, energy, critical, atlas, orbit_k, critical_orbits, fmap)
