"""What the cameras would see: I4(t) reconstructed from a simulated track, with its uncertainty.

The track: markers on the body (``markers``, body axes) at the cameras' frames (sourced frame
rate, :data:`chargedesign.physical.support.FIGURES` ``camera.*``), each position with
Gaussian noise of its own size along and across the line of sight (space axes, fixed). Per
frame the attitude is fitted to the noisy markers (Kabsch: the rotation minimising the squared
distances, batched SVD). Over windows of frames the state is fitted: the rotation vectors
``theta_k = log(R_m^T R_k)`` of the window's frames about its middle ``R_m`` are fitted by a
polynomial in ``tau`` (degree :data:`FIT_DEGREE`, least squares, per component; its linear
coefficient is omega), so omega is the body-axes rate
(``dR/dt = R hat(omega)``) and ``gamma = R_m^T e_Z``. I4 follows from the fitted states.

The uncertainty: the reconstruction is repeated over noise seeds; per window its spread and
its bias against the true I4. The comparison: a statistic of each flight, the spread of the
reconstructed I4 over the windows (standard deviation over the mean), for the integrable
release (noise and the fit's bias only) and for a control release with I3 != 0 (whose I4
moves), each over the same number of seeds: the control is told apart when its spread
exceeds the integrable one's at a given false-alarm rate; the confidence is
said as ``z = (median control - mean integrable) / sd integrable``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.flight.release import Start, perturbed
from chargedesign.formatting import ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.physical.support import figure
from chargedesign.simulation.system import quaternion_rotation, theorem_i4
from chargedesign.topology.chambers import propagate

#: frames per fitted window
WINDOW_FRAMES = 40
#: degree of the polynomial in time the rotation vectors of a window are fitted by
FIT_DEGREE = 4
#: noise seeds of the reconstruction
SEEDS = 12
#: the relative omega error of the control release
CONTROL_ERROR = 5e-2
#: false-alarm rate of the comparison (the integrable release's quantile the control must pass)
FALSE_ALARM = 0.01


@dataclass(frozen=True)
class Cameras:
    """Frame rate (Hz), marker noise across and along the line of sight (m, one standard
    deviation) and the line of sight (unit vector, space axes)."""

    frame_rate_Hz: float = figure("camera.frame_rate_Hz")
    noise_across_m: float = figure("camera.marker_noise_across_m")
    noise_along_m: float = figure("camera.marker_noise_along_m")
    line_of_sight: tuple[float, float, float] = (1.0, 0.0, 0.0)

    def to_dict(self) -> dict[str, Any]:
        return {
            "frame_rate_Hz": self.frame_rate_Hz,
            "noise_across_m": self.noise_across_m,
            "noise_along_m": self.noise_along_m,
            "line_of_sight": list(self.line_of_sight),
            "sources": [
                "camera.frame_rate_Hz",
                "camera.marker_noise_across_m",
                "camera.marker_noise_along_m",
            ],
        }


def default_markers(radius: float) -> np.ndarray:
    """Eight markers at the corners of a cube inscribed in the sphere of ``radius`` (m), body
    axes, shape (8, 3): no two share a line through O, so every frame fixes the attitude."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return corners * radius / np.sqrt(3.0)


def noisy_track(
    rotations: np.ndarray, markers: np.ndarray, cameras: Cameras, rng: np.random.Generator
) -> np.ndarray:
    """Marker positions seen at each frame (T, k, 3), space axes, with the cameras' noise."""
    seen = np.einsum("tij,kj->tki", rotations, markers)
    los = np.asarray(cameras.line_of_sight, dtype=float)
    los /= np.linalg.norm(los)
    noise = rng.normal(size=seen.shape) * cameras.noise_across_m
    along = rng.normal(size=seen.shape[:2]) * cameras.noise_along_m
    across = noise - np.einsum("tki,i->tk", noise, los)[..., None] * los
    return seen + across + along[..., None] * los


def fit_attitudes(seen: np.ndarray, markers: np.ndarray) -> np.ndarray:
    """The body-to-space rotation of each frame fitted to the seen markers (T, k, 3): Kabsch,
    batched, shape (T, 3, 3)."""
    a = seen - seen.mean(axis=1, keepdims=True)
    b = markers - markers.mean(axis=0)
    H = np.einsum("kj,tki->tji", b, a)  # sum_k b_k a_k^T
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.einsum("tij,tjk->tik", U, Vt)))
    D = np.zeros((len(seen), 3, 3))
    D[:, 0, 0] = D[:, 1, 1] = 1.0
    D[:, 2, 2] = d
    return np.einsum("tji,tjk,tlk->til", Vt, D, U)  # V D U^T


def fit_states(
    times: np.ndarray, rotations: np.ndarray, window: int = WINDOW_FRAMES, degree: int = FIT_DEGREE
):
    """States fitted over consecutive windows of ``window`` frames: the windows' middle times
    (n,) and states (n, 6) ``(p, q, r, gamma1, gamma2, gamma3)``."""
    # here, not at import: the design command imports this module for every scene (the
    # flight record), a flight only in free fall; scipy.spatial is heavy (tests/test_startup.py)
    from scipy.spatial.transform import Rotation

    count = len(times) // window
    mids, states = [], []
    for w in range(count):
        rows = slice(w * window, (w + 1) * window)
        t = times[rows]
        R = rotations[rows]
        middle = window // 2
        tau = t - t[middle]
        theta = Rotation.from_matrix(np.einsum("ji,tjk->tik", R[middle], R)).as_rotvec()
        design = np.column_stack([tau**j for j in range(degree + 1)])
        coef, *_ = np.linalg.lstsq(design, theta, rcond=None)
        centre = R[middle] @ Rotation.from_rotvec(coef[0]).as_matrix()
        mids.append(t[middle])
        states.append(np.concatenate([coef[1], centre[2, :]]))
    return np.array(mids), np.array(states)


def spread(i4: np.ndarray) -> np.ndarray:
    """The spread of I4 over a flight's windows: the standard deviation over the mean's
    magnitude, of each row of windowed I4 values (s, n)."""
    return np.std(i4, axis=1) / np.abs(np.mean(i4, axis=1))


@dataclass
class Observation:
    """The reconstruction of I4(t) from the cameras, and the comparison with a control.

    ``times`` (n,): the windows' middles; ``truth`` (n,): the integrable release's I4 there;
    ``mean``, ``sigma`` (n,): the reconstructed I4 over the seeds (mean and standard
    deviation); ``integrable`` and ``control`` (seeds,): the measured I4 spread of each seed's
    flight; ``control_truth``: the control's true spread; ``z``: the control's median measured
    spread above the integrable one's mean, in its standard deviations; ``detected``: the
    share of control flights whose spread passes the integrable flights' ``1 - FALSE_ALARM``
    quantile (with few seeds, about the largest integrable spread)."""

    cameras: Cameras
    marker_radius_m: float
    window_frames: int
    times: np.ndarray
    truth: np.ndarray
    mean: np.ndarray
    sigma: np.ndarray
    integrable: np.ndarray
    control: np.ndarray
    control_error: float
    control_truth: float
    z: float
    detected: float

    @property
    def relative_sigma(self) -> float:
        """The reconstruction's typical relative uncertainty of one window's I4."""
        return float(np.median(self.sigma / np.abs(self.truth)))

    @property
    def relative_bias(self) -> float:
        return float(np.max(np.abs(self.mean - self.truth)) / np.abs(self.truth[0]))

    def to_dict(self) -> dict[str, Any]:
        return {
            "cameras": self.cameras.to_dict(),
            "marker_radius_m": self.marker_radius_m,
            "window_frames": self.window_frames,
            "windows": len(self.times),
            "I4_relative_sigma": self.relative_sigma,
            "I4_relative_bias": self.relative_bias,
            "integrable_measured_spread_mean": float(np.mean(self.integrable)),
            "integrable_measured_spread_sd": float(np.std(self.integrable)),
            "control_omega_error": self.control_error,
            "control_true_spread": self.control_truth,
            "control_measured_spread_median": float(np.median(self.control)),
            "z": self.z,
            "detected_share": self.detected,
            "false_alarm": FALSE_ALARM,
        }

    def __str__(self) -> str:
        return (
            f"cameras at {fmt(self.cameras.frame_rate_Hz)} Hz, markers "
            f"{fmt(self.cameras.noise_across_m * 1e3)} mm across / "
            f"{fmt(self.cameras.noise_along_m * 1e3)} mm along the line of sight, at "
            f"{fmt(self.marker_radius_m, ROUGH)} m: I4 reconstructed to "
            f"{fmt(self.relative_sigma, ROUGH)} per {self.window_frames}-frame window (bias "
            f"{fmt(self.relative_bias, ROUGH)}); the integrable release's measured I4 spread "
            f"{fmt(float(np.mean(self.integrable)), ROUGH)} +- "
            f"{fmt(float(np.std(self.integrable)), ROUGH)}, the control's (omega off by "
            f"{fmt(self.control_error)}, true spread {fmt(self.control_truth, ROUGH)}) "
            f"{fmt(float(np.median(self.control)), ROUGH)}: {fmt(self.z, ROUGH)} sigma apart, "
            f"told apart in {fmt(100 * self.detected, ROUGH)} % of flights at "
            f"{fmt(100 * FALSE_ALARM)} % false alarms"
        )


def observe(
    params: Parameters,
    start: Start,
    marker_radius: float,
    *,
    cameras: Cameras | None = None,
    window: int = WINDOW_FRAMES,
    degree: int = FIT_DEGREE,
    seeds: int = SEEDS,
    control_error: float = CONTROL_ERROR,
    seed: int = 0,
) -> Observation:
    """Reconstruct I4(t) of the release ``start`` and of a control release (omega off by
    ``control_error`` |omega|, so I3 != 0) from simulated camera tracks over ``seeds`` noise
    seeds (``seed`` the first), markers at ``marker_radius`` (m)."""
    cameras = cameras or Cameras()
    frames = round(start.flight_s * cameras.frame_rate_Hz) + 1
    control = perturbed(start.state, control_error, 1, seed + 7919)[0]
    times, states, quats = propagate(
        params, np.stack([start.state, control]), start.flight_s, frames
    )
    markers = default_markers(marker_radius)
    rng = np.random.default_rng(seed)
    ranges: list[list[float]] = [[], []]
    windows_i4 = []
    mids = np.zeros(0)
    for which in (0, 1):
        R = quaternion_rotation(quats[which])
        for _ in range(seeds):
            fitted = fit_attitudes(noisy_track(R, markers, cameras, rng), markers)
            mids, fitted_states = fit_states(times, fitted, window, degree)
            i4 = theorem_i4(fitted_states, params)
            ranges[which].append(float(spread(i4[None, :])[0]))
            if which == 0:
                windows_i4.append(i4)
    i4_all = np.array(windows_i4)
    truth_states = states[0][[int(np.argmin(np.abs(times - t))) for t in mids]]
    truth = theorem_i4(truth_states, params)
    control_i4 = theorem_i4(states[1], params)
    control_truth = float(spread(control_i4[None, :])[0])
    base, other = np.array(ranges[0]), np.array(ranges[1])
    sd = float(np.std(base)) or float(np.finfo(float).tiny)
    z = (float(np.median(other)) - float(np.mean(base))) / sd
    threshold = float(np.quantile(base, 1.0 - FALSE_ALARM))
    return Observation(
        cameras,
        marker_radius,
        window,
        mids,
        truth,
        i4_all.mean(axis=0),
        i4_all.std(axis=0),
        base,
        other,
        control_error,
        control_truth,
        z,
        float(np.mean(other > threshold)),
    )
