"""The loop as built: sampled control with delay, sensors, wheel limits, disturbances.

At each sample ``t_k = k / rate`` the controller reads its sensors (:class:`Sensing`: the
gyro, ``omega + bias + white noise`` with the bias calibrated at rest; the attitude sensor's
frames fused with the gyro; the wheels' encoders; the centre-of-mass estimator), computes a
command and holds it from ``t_k + delay`` to ``t_{k+1} + delay``:

- ``zoh``: the law ``h' = -J f - omega x (J omega + h)`` at the measured state;
- ``predictive``: the model's own motion (the continuous loop, from the measured state)
  predicted over the delay and the coming interval, and the average of its ``h'`` there,
  ``(h(t_k + delay + T) - h(t_k + delay)) / T``;

less a known bearing drag fed forward (``- b_ff omega_measured``), when given, plus the
estimator's weight torque, bending and drag fed forward.

The commanded body torque is shared among the wheels (least-norm), each wheel's torque
saturated and quantised, then limited so that no wheel's momentum passes its limit by the
end of the interval the torque is held (a wheel at its momentum limit delivers no torque
that would push it further; its momentum is tracked per wheel), delivered by the motors
(:class:`Motors`: ideal, or a lag with friction), and the plant integrated (fixed-step
DOP853) with the bearing's viscous drag ``-b omega`` and the weight's torque
``-M g (r_c + K gamma) x gamma`` of a centre of mass at ``r_c`` moved by the mounts' bending
``K gamma``. Runs of one ensemble go together as one batch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from chargedesign.airbearing.dynamics import CaseModel, Plant, invariants
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import SolverError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.sampling import fibonacci_sphere
from chargedesign.simulation.direct import cross
from chargedesign.simulation.integrate import solve

#: the longest fixed DOP853 step, in units of 1 / (the motion's fastest rate): local errors
#: of order (0.05)^9 ~ 2e-12 per step
STEP_FRACTION = 0.05
#: the integrator service's method between control samples: the held command makes the
#: right-hand side smooth there, and fixed steps cost less than adaptive ones for the same
#: drift (measured in docs/testbed.md, "The plant's integrator")
PIECE_METHOD = "fixed-DOP853"
#: the adaptive methods' tolerances (continuous loop, theorem's motion, and a PIECE_METHOD
#: other than the fixed one)
RTOL = 1e-12
#: |omega| beyond this many times the motion's fastest rate: the loop has diverged
DIVERGED = 1e3


@dataclass(frozen=True)
class LoopSettings:
    """One loop configuration (SI units)."""

    rate_Hz: float
    delay_s: float
    t_end_s: float
    command: str = "zoh"
    gyro_arw: float | np.ndarray = 0.0
    gyro_bias: float | np.ndarray = 0.0
    attitude_noise: float = 0.0
    imbalance_m: float = 0.0
    imbalance_direction: tuple[float, float, float] | None = None  # None: random per run
    drag_N_m_s: float = 0.0
    drag_feedforward_N_m_s: float = 0.0  # the drag the controller knows and cancels
    total_mass_kg: float = 0.0
    wheel_axes: np.ndarray = field(default_factory=lambda: np.eye(3))
    max_torque: float = np.inf
    max_momentum: float = np.inf  # each wheel's stored momentum limit, N m s
    resolution: float = 0.0
    #: K (3x3): the mounts move the centre of mass by K gamma (m) as gravity turns
    compliance: np.ndarray | None = None
    #: attitude frames per second (held between frames; inf: one per sample)
    attitude_rate_Hz: float = np.inf
    #: the wheels' momentum read by encoders to this step, N m s (0: exact)
    encoder_step: float = 0.0
    #: fuse the attitude frames with the gyro (complementary filter)
    fusion: bool = False
    #: the attitude blend per frame
    fusion_gain: float = 0.1
    #: the gyro's bias is estimated by averaging it at rest for this long before the run (s;
    #: 0: not estimated): what is left is ``N / sqrt(t)`` for angle random walk N
    bias_calibration_s: float = 0.0
    #: the motors' torque bandwidth (Hz; inf: ideal torque sources) and each wheel's
    #: Coulomb friction (N m, against its momentum's sign)
    motor_bandwidth_Hz: float = np.inf
    wheel_friction_N_m: float = 0.0
    #: estimate the centre-of-mass offset and the drag online (RLS) and feed them forward
    estimator: bool = False
    #: the RLS prior: offset (m), drag (N m s) and compliance (each entry of K, m)
    #: standard deviations
    prior_offset_m: float = 1e-4
    prior_drag_N_m_s: float = 1e-3
    prior_compliance_m: float = 0.0

    @property
    def noisy(self) -> bool:
        return bool(np.any(self.gyro_arw) or np.any(self.gyro_bias) or self.attitude_noise > 0)

    @property
    def disturbed(self) -> bool:
        return bool(
            self.drag_N_m_s != 0.0 or self.imbalance_m != 0.0 or self.compliance is not None
        )

    def per_run(self, name: str, runs: int) -> np.ndarray:
        """A gyro figure as a column (runs, 1): one value for all runs, or one per run."""
        return np.broadcast_to(np.asarray(getattr(self, name), float), (runs,))[:, None]


@dataclass
class LoopRun:
    """An ensemble of closed-loop runs.

    Attributes
    ----------
    times : ndarray, shape (N + 1,)
        The sample instants, s.
    states : ndarray, shape (m, N + 1, 6) or None
        The true (omega, gamma) of every run at the samples (kept when asked).
    I4_drift : ndarray, shape (m,)
        ``max_t |I4(t) - I4(0)| / |I4(0)|`` over the samples.
    I4_drift_curve : ndarray, shape (m, N + 1)
        ``|I4(t) - I4(0)| / |I4(0)|``.
    I3_max : ndarray, shape (m,)
        ``max_t |I3(t)|``, J s (the runs start on I3 = 0).
    wheel_torque_max, wheel_momentum_max : ndarray, shape (m,)
        The largest |torque| (N m) and |momentum| (N m s) of any wheel.
    """

    times: np.ndarray
    states: np.ndarray | None
    I4_drift: np.ndarray
    I4_drift_curve: np.ndarray
    I3_max: np.ndarray
    wheel_torque_max: np.ndarray
    wheel_momentum_max: np.ndarray
    wheel_momentum: np.ndarray | None = None
    #: the estimate's centre-of-mass error (m), (m, S), at the samples ``offset_error_index``
    #: (S,), when estimated
    offset_error: np.ndarray | None = None
    offset_error_index: np.ndarray | None = None
    #: |estimated - true| gyro bias at the end, rad/s (m,), when fused
    bias_error: np.ndarray | None = None

    @property
    def t_simulated_s(self) -> float:
        return float(self.times[-1])


def initial_state(
    params: Parameters, gamma: np.ndarray, p: float, q: float, case: CaseModel | None = None
) -> np.ndarray:
    """``(p, q, r, gamma)`` on the flown model's level, r solved from the linear ``I3 =
    level``: the theorem's I3 = 0, ``(I omega + l) . gamma = 0`` (``params``), or the
    ``case``'s level (:meth:`~chargedesign.airbearing.dynamics.CaseModel.initial_state`;
    ``params`` unused)."""
    g = np.asarray(gamma, float) / np.linalg.norm(gamma)
    if abs(g[2]) < 1e-8:
        # the scene's start is refused at reading (TestbedOptions): a caller's misuse here
        if case is None:
            raise ValueError("initial_state: gamma3 must be non-zero to solve r from I3 = 0")
        raise ValueError(
            f"testbed.initial_gamma: gamma3 must be non-zero to solve r from case {case.name}'s "
            f"level I3 = {fmt(case.level_value, PRECISE)}"
        )
    if case is not None:
        return case.initial_state(g, p, q)
    l_vec = evaluators.angular_potential(g, params)
    C = params.C
    r = -(2.0 * C * (p * g[0] + q * g[1]) + float(l_vec @ g)) / (C * g[2])
    return np.array([p, q, r, *g])


def relative_drift(curve_I4: np.ndarray) -> np.ndarray:
    """``|I4(t) - I4(0)| / |I4(0)|`` along the last axis."""
    i4_0 = curve_I4[..., :1]
    return np.abs(curve_I4 - i4_0) / np.where(i4_0 != 0.0, np.abs(i4_0), 1.0)


class Actuator:
    """Least-norm share of a body torque among the wheels, torque saturation,
    quantisation, and momentum saturation."""

    def __init__(self, settings: LoopSettings) -> None:
        self.axes = np.asarray(settings.wheel_axes, float)  # (k, 3)
        self.share = np.linalg.pinv(self.axes.T)  # (k, 3): body torque -> wheel torques
        self.max_torque = settings.max_torque
        self.max_momentum = settings.max_momentum
        self.resolution = settings.resolution

    def wheel(self, body: np.ndarray) -> np.ndarray:
        return body @ self.share.T

    def apply(
        self, body: np.ndarray, momentum: np.ndarray | None = None, hold: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """(body torque actually applied (m, 3), wheel torques (m, k)).

        With the wheels' ``momentum`` (m, k) at the start of a hold of ``hold`` s, each
        wheel's torque is limited so that its momentum stays within ``max_momentum`` by the
        hold's end (after quantisation: the limit is the wheel's speed limit, a hard stop).
        """
        tau = np.clip(self.wheel(body), -self.max_torque, self.max_torque)
        if self.resolution > 0.0:
            tau = np.round(tau / self.resolution) * self.resolution
        if momentum is not None and hold > 0.0 and np.isfinite(self.max_momentum):
            room_up = np.maximum(self.max_momentum - momentum, 0.0) / hold
            room_down = np.minimum(-self.max_momentum - momentum, 0.0) / hold
            tau = np.clip(tau, room_down, room_up)
        return tau @ self.axes, tau


def run_loop(
    plant: Plant,
    x0: np.ndarray,
    settings: LoopSettings,
    runs: int = 1,
    seed: int = 0,
    keep_states: bool = False,
) -> LoopRun:
    """``runs`` closed-loop runs from ``x0 = (omega, gamma)`` (wheels at rest), one batch.

    The noise of the runs comes from one generator seeded by ``seed`` (run i of the same
    seed and count is reproducible).
    """
    rng = np.random.default_rng(seed)
    T = 1.0 / settings.rate_Hz
    n_samples = max(1, round(settings.t_end_s * settings.rate_Hz))
    rate = plant.motion_rate(x0[:3])
    max_step = STEP_FRACTION / rate
    actuator = Actuator(settings)
    bias = settings.per_run("gyro_bias", runs) * rng.standard_normal((runs, 3))
    arw = settings.per_run("gyro_arw", runs)
    offset = _imbalance(settings.imbalance_m, runs, rng, settings.imbalance_direction)
    weight = settings.total_mass_kg * STANDARD_GRAVITY

    def external(x: np.ndarray) -> np.ndarray | None:
        if not settings.disturbed:
            return None
        com = offset if settings.compliance is None else offset + x[:, 3:6] @ settings.compliance.T
        return -settings.drag_N_m_s * x[:, 0:3] - weight * cross(com, x[:, 3:6])

    x = np.zeros((runs, 9))
    x[:, 0:6] = x0[:6]
    _, held_wheel = actuator.apply(plant.command(x))  # the loop was running before t = 0
    motors = Motors(settings, held_wheel)
    wheel_h = np.zeros((runs, len(actuator.axes)))  # each wheel's momentum, N m s
    states = np.empty((runs, n_samples + 1, 6))
    momentum = np.empty((runs, n_samples + 1))
    torque_max = np.zeros(runs)
    sensing = Sensing(settings, runs, T, bias, arw, rng, plant, weight)
    # a diverging run overflows before it is caught at the next sample: named there
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(n_samples + 1):
            if not np.isfinite(x).all() or np.abs(x[:, 0:3]).max() > DIVERGED * rate:
                raise _diverged(k * T)
            states[:, k] = x[:, 0:6]
            momentum[:, k] = np.abs(wheel_h).max(axis=1)
            if k == n_samples:
                break
            measured = sensing.read(x, k, actuator.axes)
            wanted = _command(plant, measured, settings, T, max_step) + sensing.feed_forward(
                measured
            )
            # the new torque acts from t_k + delay for one period: room left then
            at_switch = wheel_h + held_wheel * settings.delay_s
            _, tau = actuator.apply(wanted, at_switch, T)
            torque_max = np.maximum(torque_max, np.abs(tau).max(axis=1))
            for command, dt in ((held_wheel, settings.delay_s), (tau, T - settings.delay_s)):
                delivered = motors.piece(command, dt, wheel_h)
                try:
                    x = _piece(_held(plant, delivered @ actuator.axes, external), x, dt, max_step)
                except SolverError as exc:  # non-finite states within the piece
                    raise _diverged((k + 1) * T) from exc
                wheel_h = wheel_h + delivered * dt
            held_wheel = tau
    I3, I4 = plant.invariants(states)
    curve = relative_drift(I4)
    errors = sensing.offset_errors(offset) if settings.estimator else None
    return LoopRun(
        times=np.arange(n_samples + 1) * T,
        states=states if keep_states else None,
        I4_drift=curve.max(axis=1),
        I4_drift_curve=curve,
        I3_max=np.abs(I3).max(axis=1),
        wheel_torque_max=torque_max,
        wheel_momentum_max=momentum.max(axis=1),
        wheel_momentum=momentum if keep_states else None,
        offset_error=errors[1] if errors is not None else None,
        offset_error_index=errors[0] if errors is not None else None,
        bias_error=np.linalg.norm(sensing.bias_hat - bias, axis=1)
        if settings.bias_calibration_s > 0.0
        else None,
    )


class Motors:
    """What the wheels' motors deliver over a piece of time under a held command (m, k):
    a first-order lag of bandwidth f (time constant ``1 / (2 pi f)``), whose average over the
    piece ``c + (tau0 - c) (t_c / dt) (1 - exp(-dt / t_c))`` gives the piece its exact
    impulse, less each wheel's Coulomb friction against its momentum's sign."""

    def __init__(self, settings: LoopSettings, torque: np.ndarray) -> None:
        self.torque = torque.copy()
        self.constant = (
            1.0 / (2.0 * np.pi * settings.motor_bandwidth_Hz)
            if np.isfinite(settings.motor_bandwidth_Hz)
            else 0.0
        )
        self.friction = settings.wheel_friction_N_m

    def piece(self, command: np.ndarray, dt: float, momentum: np.ndarray) -> np.ndarray:
        if dt <= 0.0:
            return command
        if self.constant > 0.0:
            decay = np.exp(-dt / self.constant)
            average = command + (self.torque - command) * (self.constant / dt) * (1.0 - decay)
            self.torque = command + (self.torque - command) * decay
        else:
            average = command
            self.torque = command
        if self.friction:
            average = average - self.friction * np.sign(momentum)
        return average


def _diverged(t: float) -> SolverError:
    return SolverError(
        f"testbed: the closed loop diverged by t = {fmt(t, PRECISE)} s (|omega| beyond "
        f"{fmt(DIVERGED, PLAIN)} times the motion's rate): noise, delay or disturbances too "
        "large for this loop"
    )


def _piece(
    f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, dt: float, max_step: float
) -> np.ndarray:
    """``x`` (m, 9) advanced by ``dt`` under ``x' = f(x)`` by the integrator service."""
    if dt <= 0.0:
        return x
    return solve(
        lambda _t, y: f(y),
        x,
        (0.0, dt),
        method=PIECE_METHOD,
        max_step=max_step,
        rtol=RTOL,
        atol=RTOL,
        what="testbed: the plant between control samples",
    ).end


def _held(
    plant: Plant, torque: np.ndarray, external: Callable[[np.ndarray], np.ndarray | None]
) -> Callable[[np.ndarray], np.ndarray]:
    """The plant's right-hand side under a held wheel torque."""
    return lambda y: plant.rates(y, torque, external(y))


def _imbalance(
    size: float,
    runs: int,
    rng: np.random.Generator,
    fixed: tuple[float, float, float] | None = None,
) -> np.ndarray:
    """Centre-of-mass offsets of length ``size`` in random directions, or along ``fixed``
    (m, 3)."""
    direction = rng.standard_normal((runs, 3)) if fixed is None else np.tile(fixed, (runs, 1))
    return size * direction / np.linalg.norm(direction, axis=1, keepdims=True)


class Sensing:
    """The controller's view of the state, sample by sample (m runs at once).

    - gyro: ``omega + bias + white noise`` (per-sample deviation ``N / sqrt(T)``);
    - attitude frames: gamma turned by a small random angle, at the sensor's rate (held in
      between); with ``fusion`` a complementary filter propagates the estimate with the
      gyro, blends each frame in by ``fusion_gain`` and estimates the gyro's bias from the
      frames' innovations (``b += (T / tau) (gamma x innovation) / T_frame``: the
      innovation of a bias error e over a frame is ``-T_frame gamma x e``);
    - the wheels' momentum from encoders, quantised to ``encoder_step`` per wheel;
    - with ``estimator``: recursive least squares of ``theta = (r_c, b, K)`` (K symmetric:
      the mounts move the centre of mass by ``K gamma``) on the integrated torque balance
      between samples, ``J d omega + int omega x (J omega + h) + d h =
      int (M g gamma x (r_c + K gamma) - b omega)`` (trapezoid rule), summed from the start
      (the gyro noise then enters once, not at every difference), and the feed-forward of
      ``M g gamma x (r_c + K gamma) - b omega`` that cancels the estimated weight torque and
      drag.
    """

    def __init__(
        self,
        settings: LoopSettings,
        runs: int,
        T: float,
        bias: np.ndarray,
        arw: np.ndarray,
        rng: np.random.Generator,
        plant: Plant,
        weight: float,
    ) -> None:
        self.s, self.T, self.bias, self.arw, self.rng = settings, T, bias, arw, rng
        self.J, self.weight = plant.model_inertia, weight
        self.every = (
            max(1, round(settings.rate_Hz / settings.attitude_rate_Hz))
            if np.isfinite(settings.attitude_rate_Hz)
            else 1
        )
        self.frame: np.ndarray | None = None
        self.gamma_hat: np.ndarray | None = None
        self.bias_hat = np.zeros((runs, 3))
        if settings.bias_calibration_s > 0.0:
            self.bias_hat = bias + (
                arw / np.sqrt(settings.bias_calibration_s)
            ) * rng.standard_normal((runs, 3))
        self.last: np.ndarray | None = None
        self.theta: np.ndarray = np.zeros((runs, THETA))
        prior = np.array(
            [settings.prior_offset_m] * 3
            + [settings.prior_drag_N_m_s]
            + [max(settings.prior_compliance_m, 1e-30)] * 6
        )
        # the prior as the square-root information R = P0^(-1/2), with R theta = d = 0
        self.R = np.tile(np.diag(1.0 / prior), (runs, 1, 1))
        self.d = np.zeros((runs, THETA))
        self.Y = np.zeros((runs, 3))
        self.Phi = np.zeros((runs, 3, THETA))
        self.noise_y = max(float(np.max(arw)) / np.sqrt(T), 1e-12) * float(np.abs(self.J).max())
        self.prev: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.estimates: list[np.ndarray] = []
        self.compliance = settings.compliance

    def read(self, x: np.ndarray, k: int, wheel_axes: np.ndarray) -> np.ndarray:
        s, m = self.s, len(x)
        out = x.copy()
        if s.noisy:
            out[:, 0:3] += self.bias + (self.arw / np.sqrt(self.T)) * self.rng.standard_normal(
                (m, 3)
            )
        if k % self.every == 0 or self.frame is None:
            self.frame = x[:, 3:6].copy()
            if s.attitude_noise > 0.0:
                angle = s.attitude_noise * self.rng.standard_normal((m, 3))
                g = x[:, 3:6] + cross(angle, x[:, 3:6])
                self.frame = g / np.linalg.norm(g, axis=1, keepdims=True)
            fresh = True
        else:
            fresh = False
        out[:, 0:3] -= self.bias_hat
        if s.fusion:
            self._fuse(out, fresh)
        else:
            out[:, 3:6] = self.frame
        if s.encoder_step > 0.0:
            share = np.linalg.pinv(wheel_axes.T)
            wheels = np.round((x[:, 6:9] @ share.T) / s.encoder_step) * s.encoder_step
            out[:, 6:9] = wheels @ wheel_axes
        if s.estimator:
            self._estimate(out)
        return out

    def _fuse(self, out: np.ndarray, fresh: bool) -> None:
        assert self.frame is not None
        if self.gamma_hat is None:
            self.gamma_hat = self.frame.copy()
        elif self.last is not None:
            g = self.gamma_hat + self.T * cross(self.gamma_hat, self.last)
            self.gamma_hat = g / np.linalg.norm(g, axis=1, keepdims=True)
        if fresh:
            g = self.gamma_hat + self.s.fusion_gain * (self.frame - self.gamma_hat)
            self.gamma_hat = g / np.linalg.norm(g, axis=1, keepdims=True)
        self.last = out[:, 0:3].copy()
        out[:, 3:6] = self.gamma_hat

    def _rows(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(J omega + h... terms (m, 3), regressor (m, 3, 4)) at one sample."""
        omega, gamma, h = y[:, 0:3], y[:, 3:6], y[:, 6:9]
        gyro = cross(omega, omega @ self.J + h)
        phi = np.zeros((len(y), 3, THETA))
        for j in range(3):  # M g gamma x r: the columns gamma x e_j
            phi[:, :, j] = self.weight * cross(gamma, np.broadcast_to(np.eye(3)[j], gamma.shape))
        phi[:, :, 3] = -omega
        for j, (a, b) in enumerate(_SYMMETRIC):  # M g gamma x (E_ab gamma)
            column = np.zeros_like(gamma)
            column[:, a] += gamma[:, b]
            if a != b:
                column[:, b] += gamma[:, a]
            phi[:, :, 4 + j] = self.weight * cross(gamma, column)
        return gyro, phi

    def _estimate(self, y: np.ndarray) -> None:
        gyro, phi = self._rows(y)
        if self.prev is not None:
            prev, prev_gyro, prev_phi = self.prev
            self.Y += (
                (y[:, 0:3] - prev[:, 0:3]) @ self.J
                + 0.5 * self.T * (prev_gyro + gyro)
                + (y[:, 6:9] - prev[:, 6:9])
            )
            self.Phi += 0.5 * self.T * (prev_phi + phi)
            # RLS on the summed rows, three at a time, in square-root information form: the
            # triangle R (R^T R = P^-1) and d (R theta = d) absorb each new rows' block by
            # one QR of [[R, d], [Phi, Y] / noise]. The same least squares as the covariance
            # form P - G Phi P, but that form lost P's positive definiteness with the
            # noise-free rows (noise of order 1e-12), and the estimate then followed the BLAS
            # kernel's rounding: the noise-free run of tests/airbearing/test_mounts_and_window
            # ended with an offset error of 8e-9, 2.6e-8 or 1.8e-7 m under OpenBLAS'
            # Sandybridge, Haswell and SkylakeX kernels
            block = np.concatenate(
                [
                    np.concatenate([self.R, self.d[:, :, None]], axis=2),
                    np.concatenate([self.Phi, self.Y[:, :, None]], axis=2) / self.noise_y,
                ],
                axis=1,
            )
            upper = np.linalg.qr(block).R
            self.R, self.d = upper[:, :THETA, :THETA], upper[:, :THETA, THETA]
            self.theta = np.linalg.solve(self.R, self.d[:, :, None])[:, :, 0]
        self.prev = (y.copy(), gyro, phi)
        self.estimates.append(self.theta.copy())

    def feed_forward(self, measured: np.ndarray) -> np.ndarray:
        """The torque that cancels the estimated weight torque and drag (m, 3), or 0."""
        if not self.s.estimator:
            return np.zeros((len(measured), 3))
        gamma = measured[:, 3:6]
        com = self.theta[:, 0:3] + np.einsum("mij,mj->mi", _matrices(self.theta[:, 4:]), gamma)
        return self.weight * cross(gamma, com) - self.theta[:, 3:4] * measured[:, 0:3]

    def offset_errors(self, offset: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The largest error of the estimated centre of mass normal to gravity over all
        attitudes, ``max_gamma |(dr + dK gamma) x gamma|`` (m), at up to
        :data:`ERROR_SAMPLES` samples: (sample indices (S,), errors (m, S))."""
        every = [*self.estimates, self.estimates[-1]]
        index = np.unique(np.linspace(0, len(every) - 1, ERROR_SAMPLES).astype(int))
        est = np.stack([every[i] for i in index], axis=1)  # (m, S, THETA)
        K = np.zeros((3, 3)) if self.compliance is None else self.compliance
        dr = est[:, :, 0:3] - offset[:, None, :]
        dK = _matrices(est[:, :, 4:].reshape(-1, 6)).reshape(*est.shape[:2], 3, 3) - K
        err = dr[:, :, None, :] + np.einsum("mnij,pj->mnpi", dK, _PROBES)
        normal = err - np.einsum("mnpi,pi->mnp", err, _PROBES)[..., None] * _PROBES
        return index, np.linalg.norm(normal, axis=3).max(axis=2)


#: the samples at which the estimate's error is read
ERROR_SAMPLES = 101
#: the estimator's unknowns: r_c (3), b (1), K's upper triangle (6)
THETA = 10
_SYMMETRIC = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
#: attitudes the estimate's error is read at (a Fibonacci sphere)
_PROBES = fibonacci_sphere(200, phase=0.0)


def _matrices(k: np.ndarray) -> np.ndarray:
    """Symmetric 3x3 matrices (m, 3, 3) from upper triangles (m, 6)."""
    out = np.zeros((len(k), 3, 3))
    for j, (a, b) in enumerate(_SYMMETRIC):
        out[:, a, b] = k[:, j]
        out[:, b, a] = k[:, j]
    return out


def _command(
    plant: Plant, measured: np.ndarray, settings: LoopSettings, T: float, max_step: float
) -> np.ndarray:
    """The body torque h' to hold (m, 3), less the known drag ``b_ff omega`` (fed forward:
    the wheels then push the platform by ``+b_ff omega``)."""
    if settings.command == "zoh":
        wanted = plant.command(measured)
    else:
        start = _piece(plant.ideal_rates, measured, settings.delay_s, max_step)
        end = _piece(plant.ideal_rates, start, T, max_step)
        wanted = (end[:, 6:9] - start[:, 6:9]) / T
    if settings.drag_feedforward_N_m_s:
        wanted = wanted - settings.drag_feedforward_N_m_s * measured[:, 0:3]
    return wanted


def continuous_loop(
    plant: Plant, x0: np.ndarray, t_end: float, samples: int, rtol: float = RTOL
) -> tuple[np.ndarray, np.ndarray]:
    """The ideal continuous loop (no sampling, noise or disturbance) by adaptive DOP853.

    Returns ``(times (samples,), states (samples, 9))``.
    """
    y0 = np.zeros(9)
    y0[:6] = x0[:6]
    out = solve(
        lambda _t, y: plant.ideal_rates(y[None])[0],
        y0,
        (0.0, t_end),
        t_eval=np.linspace(0.0, t_end, samples),
        method="DOP853",
        rtol=rtol,
        atol=rtol,
        what="testbed: the continuous loop",
    )
    return out.t, out.y


__all__ = [
    "Actuator",
    "LoopRun",
    "LoopSettings",
    "Motors",
    "continuous_loop",
    "initial_state",
    "invariants",
    "relative_drift",
    "run_loop",
]
