"""An independent generator of measured-like run-up and coast-down records, and their reference.

Nothing here uses rotorid: only numpy and scipy. It makes what a rig's data acquisition
would record on a two-mode anisotropic rotor passing its critical speeds (two proximity
probes in volts, a keyphasor notch, a slow-roll record) and computes, in closed form, the
steady-state 1X response the `rotorid transient` command is checked against
(tests/test_transient.py).

Units: SI throughout (m, kg, s, N, rad, rad/s, rad/s^2, V, V/m); speeds also in rpm and
angles in degrees where a name says so (``*_rpm``, ``*_deg``).

The rotor
---------
A 2-DOF Jeffcott rotor, x horizontal, z vertical up (docs/method.md section 1.1), no
cross-coupling and no gyroscopic term::

    m x'' + cx x' + kx x = Fx(t)
    m z'' + cz z' + kz z = Fz(t)

kx != kz: two modes, one along x (natural speed sqrt(kx/m)), one along z (sqrt(kz/m)),
with damping ratios zeta = c / (2 sqrt(k m)).

The unbalance force (derived here, not copied). A point of the disk at shaft angle theta
from +z sits at r (sin theta, cos theta) from the disk centre; the shaft turns from +z
towards +x as phi grows, and the unbalance mass m_u sits at radius d and shaft angle
theta = phi + alpha, i.e. at (x, z) + d (sin theta, cos theta). Its acceleration is
(x'', z'') + d theta'' (cos theta, -sin theta) - d theta'^2 (sin theta, cos theta), with
theta' = phi', theta'' = phi''. The force it exerts on the rotor is minus its mass times
the part of that acceleration the rotor's own motion does not give (the rotor's own inertia
taken as m, as eq. (1) of docs/method.md does)::

    (Fx, Fz) = m_u d [ phi'^2 (sin, cos)(phi + alpha) + phi'' (-cos, sin)(phi + alpha) ]

i.e. Fx = m_u d (phi'^2 sin(phi+alpha) - phi'' cos(phi+alpha)) and
Fz = m_u d (phi'^2 cos(phi+alpha) + phi'' sin(phi+alpha)) [N], as in docs/method.md
section 1.2. (The brief that asked for this generator wrote the phi'' term as
``phi'' (cos, -sin)``: that is the opposite sign; the derivation above gives ``(-cos, sin)``.
On these records the phi'' term is 25 / 700000 of the phi'^2 term at the criticals.)

Steady state at constant speed w (phi = w t): with sin(u) = Re(-i e^{iu}) and
cos(u) = Re(e^{iu}), x = Re(X e^{i phi}), z = Re(Z e^{i phi}) with::

    X = -i m_u d w^2 e^{i alpha} / (kx - m w^2 + i cx w)
    Z =    m_u d w^2 e^{i alpha} / (kz - m w^2 + i cz w)

The probes
----------
A probe at angle th (from +x towards +z, docs/acquisition.md section 1) reads the
displacement towards it, d = x cos th + z sin th, so its steady-state 1X vector is
``V = X cos th + Z sin th`` [m, zero-to-peak]: its 1X signal is Re(V e^{i phi}), phi = 0 at
the keyphasor event, phase lag -arg V. Its voltage::

    V_probe = V_dc + s (d + r(phi)) + noise,   s = 7874 V/m, V_dc = -8 V

then quantised to 16 bits over -10..+10 V (0.305 mV = 38.8 nm per step).

Runout r(phi): a profile fixed to the shaft surface, R(psi) = a1 cos(psi - b1) +
a2 cos(2 psi - b2) [m], psi the body angle (from the keyphasor mark, in the sense of
rotation). The probe's direction is the shaft angle theta_p = 90 deg - th (from +z in the
sense of rotation); the surface point facing it is the body angle psi = theta_p - phi, so
the probe reads R(theta_p - phi) = a1 cos(phi + b1 - theta_p) + a2 cos(2 phi + b2 - 2 theta_p):
its 1X runout vector is a1 e^{i (b1 - theta_p)} and its 2X one a2 e^{i (b2 - 2 theta_p)}
(same amplitudes at both probes, phases differing by the probes' angle and twice it).

The keyphasor
-------------
A notch: 0 V baseline, -5 V in the notch, which spans the shaft angles
phi in [2 pi n, 2 pi n + width) (falling edge at phi = 0 mod 2 pi, the keyphasor event). The
ideal notch is smoothed in time by a Gaussian of standard deviation ``kp_edge_s`` (the
probe's and the acquisition's bandwidth: without it the edge time would be quantised to
the sample), so the signal crosses the mid level -2.5 V exactly at the event times; then
white noise and the same 16-bit quantisation.

The records
-----------
- run-up: phi'' = accel > 0 constant from rpm_start to rpm_end; the initial state is the
  steady state at rpm_start (a slow roll running into the ramp, so no start transient);
- coast-down: phi'' = -accel from rpm_end down to rpm_start, from the steady state at
  rpm_end;
- slow roll: constant speed rpm_start for ``slow_roll_s`` seconds, from its steady state.

Each is integrated with scipy.integrate.solve_ivp (DOP853, rtol 1e-10, atol 1e-16 m) on
the state (x, z, x', z'), phi(t) = phi0 + w0 t + accel t^2 / 2 in closed form, and
sampled at ``rate_hz``; files are CSV ``t,probe_L,probe_R,kp`` (probe_L at 135 deg,
probe_R at 45 deg) and a scenario TOML with only an [acquisition] table
(docs/acquisition.md section 8).

Run ``python transient_rig.py`` to print the reference, self-test the integrator against
the closed form and time the generation.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import optimize
from scipy.integrate import solve_ivp
from scipy.special import erf

RPM = math.pi / 30.0  # rad/s per rpm
RTOL = 1e-10
ATOL = 1e-16  # m and m/s: below every state's rounding


# --------------------------------------------------------------------------- the rotor


@dataclass(frozen=True)
class Rotor:
    """The two-mode anisotropic Jeffcott rotor.

    m [kg], kx, kz [N/m], zeta_x, zeta_z [-] (damping ratios of the x and z modes),
    mud = m_u d [kg m] (unbalance), alpha_deg [deg] (its shaft angle from the keyphasor
    mark, in the sense of rotation).
    """

    m: float = 10.0
    kx: float = 4.0e6
    kz: float = 6.0e6
    zeta_x: float = 0.025
    zeta_z: float = 0.03
    mud: float = 2.5e-5
    alpha_deg: float = 30.0

    @property
    def wx(self) -> float:
        """Natural speed of the x mode, sqrt(kx/m) [rad/s]."""
        return math.sqrt(self.kx / self.m)

    @property
    def wz(self) -> float:
        """Natural speed of the z mode, sqrt(kz/m) [rad/s]."""
        return math.sqrt(self.kz / self.m)

    @property
    def cx(self) -> float:
        """Damping in x, 2 zeta_x sqrt(kx m) [N s/m]."""
        return 2.0 * self.zeta_x * math.sqrt(self.kx * self.m)

    @property
    def cz(self) -> float:
        """Damping in z, 2 zeta_z sqrt(kz m) [N s/m]."""
        return 2.0 * self.zeta_z * math.sqrt(self.kz * self.m)

    @property
    def alpha(self) -> float:
        """Unbalance angle [rad]."""
        return math.radians(self.alpha_deg)


def unbalance_force(rotor: Rotor, phi, w, wdot):
    """The unbalance force on the rotor (Fx, Fz) [N] at shaft angle phi [rad], speed
    w = phi' [rad/s] and acceleration wdot = phi'' [rad/s^2] (scalars or arrays):
    m_u d (w^2 (sin, cos)(phi + alpha) + wdot (-cos, sin)(phi + alpha)), derived in the
    module docstring."""
    th = phi + rotor.alpha
    s, c = np.sin(th), np.cos(th)
    return rotor.mud * (w * w * s - wdot * c), rotor.mud * (w * w * c + wdot * s)


def steady_state_xz(rotor: Rotor, w):
    """Closed-form steady-state 1X vectors (X, Z) [m, complex, zero-to-peak] at constant
    speed w [rad/s] (scalar or array): x = Re(X e^{i phi}), z = Re(Z e^{i phi})."""
    w = np.asarray(w, dtype=float)
    f = rotor.mud * w * w * np.exp(1j * rotor.alpha)
    X = -1j * f / (rotor.kx - rotor.m * w * w + 1j * rotor.cx * w)
    Z = f / (rotor.kz - rotor.m * w * w + 1j * rotor.cz * w)
    return X, Z


def steady_state_probe(rotor: Rotor, w, angle_deg: float):
    """Closed-form steady-state 1X vector [m, complex, zero-to-peak] of a probe at
    angle_deg [deg] (from +x towards +z) at speed w [rad/s]: X cos th + Z sin th, runout
    excluded. Its phase lag is -arg of it."""
    X, Z = steady_state_xz(rotor, w)
    th = math.radians(angle_deg)
    return X * math.cos(th) + Z * math.sin(th)


# --------------------------------------------------------------------------- the rig


@dataclass(frozen=True)
class Probe:
    """A proximity probe: its CSV column, angle_deg [deg] from +x towards +z,
    sensitivity [V/m] (> 0: the output rises as the shaft comes closer), v_dc [V] (the
    gap voltage at the rotor's rest position)."""

    column: str
    angle_deg: float
    sensitivity: float = 7874.0
    v_dc: float = -8.0


@dataclass(frozen=True)
class Rig:
    """The acquisition.

    probes: the probes (probe_L at 135 deg, probe_R at 45 deg); rate_hz [Hz];
    noise_v [V RMS] white noise on each probe; bits, range_v [V]: the ADC (range_v =
    (lo, hi)); runout: a1_m, a2_m [m] the 1X and 2X amplitudes of the shaft-surface
    profile, b1_deg, b2_deg [deg] its phases (module docstring); keyphasor: kp_column,
    kp_baseline_v [V], kp_depth_v [V] (the notch goes to baseline - depth), kp_width_deg
    [deg] (the notch's angular width), kp_edge_s [s] (Gaussian smoothing of the edges),
    kp_noise_v [V RMS].
    """

    probes: tuple[Probe, ...] = (Probe("probe_L", 135.0), Probe("probe_R", 45.0))
    rate_hz: float = 10_000.0
    noise_v: float = 5e-3
    bits: int = 16
    range_v: tuple[float, float] = (-10.0, 10.0)
    a1_m: float = 3e-6
    a2_m: float = 1e-6
    b1_deg: float = 70.0
    b2_deg: float = -40.0
    kp_column: str = "kp"
    kp_baseline_v: float = 0.0
    kp_depth_v: float = 5.0
    kp_width_deg: float = 15.0
    kp_edge_s: float = 70e-6
    kp_noise_v: float = 5e-3

    def runout_vectors(self, probe: Probe) -> tuple[complex, complex]:
        """The runout probe sees as (1X, 2X) vectors [m, complex, zero-to-peak] in the
        convention Re(V e^{i h phi}): a1 e^{i (b1 - theta_p)}, a2 e^{i (b2 - 2 theta_p)},
        theta_p = 90 deg - angle_deg the probe's shaft angle (module docstring)."""
        theta_p = math.radians(90.0 - probe.angle_deg)
        r1 = self.a1_m * complex(np.exp(1j * (math.radians(self.b1_deg) - theta_p)))
        r2 = self.a2_m * complex(np.exp(1j * (math.radians(self.b2_deg) - 2 * theta_p)))
        return r1, r2

    @property
    def lsb_v(self) -> float:
        """The ADC step [V]."""
        return (self.range_v[1] - self.range_v[0]) / 2**self.bits


def quantise(v: np.ndarray, rig: Rig) -> np.ndarray:
    """v [V] rounded to the rig's ADC (rig.bits over rig.range_v, clipped) [V]."""
    lo, hi = rig.range_v
    code = np.clip(np.round((v - lo) / rig.lsb_v), 0, 2**rig.bits - 1)
    return lo + code * rig.lsb_v


# --------------------------------------------------------------------------- speed


@dataclass(frozen=True)
class Sweep:
    """A constant-acceleration speed profile: from rpm_from to rpm_to [rpm] at |accel|
    [rad/s^2] (the sign follows the direction; accel = 0 with duration_s [s] for a
    constant speed); phi0 [rad] is the shaft angle at t = 0 (a record starts at any angle)."""

    rpm_from: float
    rpm_to: float
    accel: float = 0.0
    duration_s: float | None = None
    phi0: float = 0.0

    @property
    def w0(self) -> float:
        """Start speed [rad/s]."""
        return self.rpm_from * RPM

    @property
    def a(self) -> float:
        """phi'' [rad/s^2], signed."""
        if self.rpm_to == self.rpm_from:
            return 0.0
        return math.copysign(abs(self.accel), self.rpm_to - self.rpm_from)

    @property
    def duration(self) -> float:
        """Length of the record [s]."""
        if self.a == 0.0:
            assert self.duration_s is not None, "a constant speed needs duration_s"
            return self.duration_s
        return (self.rpm_to - self.rpm_from) * RPM / self.a

    def phi(self, t):
        """Shaft angle [rad] at t [s]: phi0 + w0 t + a t^2 / 2."""
        return self.phi0 + self.w0 * t + 0.5 * self.a * t * t

    def w(self, t):
        """Speed [rad/s] at t [s]."""
        return self.w0 + self.a * t

    def time_at(self, phi) -> np.ndarray:
        """The time [s] at which the shaft angle is phi [rad] (array), in closed form
        (the root of the quadratic on the speed's branch: t = 2 p / (w0 + sqrt(w0^2 + 2 a p)),
        p = phi - phi0, no cancellation); NaN where the speed never gets there."""
        p = np.asarray(phi, dtype=float) - self.phi0
        if self.a == 0.0:
            return p / self.w0
        disc = self.w0**2 + 2 * self.a * p
        with np.errstate(invalid="ignore"):
            return np.where(disc > 0, 2 * p / (self.w0 + np.sqrt(np.where(disc > 0, disc, 0.0))), np.nan)

    def revolutions(self) -> tuple[int, int]:
        """(first, last) n with phi = 2 pi n inside the record [0, duration]."""
        first = math.ceil(self.phi0 / (2 * math.pi) - 1e-12)
        last = math.floor(self.phi(self.duration) / (2 * math.pi) + 1e-12)
        return first, last

    def event_times(self) -> np.ndarray:
        """Times [s] at which phi = 2 pi n (the keyphasor events) within the record."""
        first, last = self.revolutions()
        return self.time_at(2 * math.pi * np.arange(first, last + 1))


# --------------------------------------------------------------------------- integration


def integrate(rotor: Rotor, sweep: Sweep, t: np.ndarray) -> np.ndarray:
    """The rotor's motion on the sweep, sampled at t [s] (from 0): array (4, len(t)) of
    x, z [m], x', z' [m/s]. DOP853, rtol 1e-10, atol 1e-16; initial state the closed-form
    steady state at the start speed (position and velocity of Re(V e^{i phi}) at phi = 0)."""
    m, kx, kz, cx, cz = rotor.m, rotor.kx, rotor.kz, rotor.cx, rotor.cz
    mud, alpha, w0, a, phi0 = rotor.mud, rotor.alpha, sweep.w0, sweep.a, sweep.phi0
    sin, cos = math.sin, math.cos

    def rhs(tt, y):
        x, z, vx, vz = y.tolist()
        w = w0 + a * tt
        th = phi0 + (w0 + 0.5 * a * tt) * tt + alpha
        s, c = sin(th), cos(th)
        fx = mud * (w * w * s - a * c)
        fz = mud * (w * w * c + a * s)
        return [vx, vz, (fx - cx * vx - kx * x) / m, (fz - cz * vz - kz * z) / m]

    X, Z = steady_state_xz(rotor, w0)
    e0 = complex(np.exp(1j * sweep.phi0))
    y0 = [(X * e0).real, (Z * e0).real, (1j * w0 * X * e0).real, (1j * w0 * Z * e0).real]
    sol = solve_ivp(rhs, (0.0, float(t[-1])), y0, method="DOP853", rtol=RTOL, atol=ATOL, t_eval=t)
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol.y


# --------------------------------------------------------------------------- records


@dataclass
class Record:
    """A generated record: t [s]; columns {name: volts [V]} in CSV order (the probes, then
    the keyphasor); and the truth: phi [rad], w [rad/s], x, z [m] (noise-free motion),
    events [s] (keyphasor event times), the sweep and the rig."""

    t: np.ndarray
    columns: dict[str, np.ndarray]
    phi: np.ndarray
    w: np.ndarray
    x: np.ndarray
    z: np.ndarray
    events: np.ndarray
    sweep: Sweep
    rig: Rig
    seconds: float = 0.0  # generation time [s]

    def write_csv(self, path: Path) -> Path:
        """Write ``t,<probe columns>,<kp>`` [s, V] to path (t with 6 decimals, volts with
        6: 1/300 of the ADC step); returns path."""
        names = list(self.columns)
        data = np.column_stack([self.t, *self.columns.values()])
        np.savetxt(path, data, fmt="%.6f", delimiter=",", header=",".join(["t", *names]), comments="")
        return Path(path)


def make_record(rotor: Rotor, rig: Rig, sweep: Sweep, seed: int, keyphasor: bool = True) -> Record:
    """Generate one record of the sweep: the rotor integrated (``integrate``), each probe's
    volts (gap, displacement towards it, runout, white noise, 16 bits) and the keyphasor
    notch (or, keyphasor=False, its baseline with noise only: a record without pulses).
    Deterministic: numpy Generator seeded with seed. Units: see ``Record``."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    n = int(math.floor(sweep.duration * rig.rate_hz + 1e-9)) + 1
    t = np.arange(n) / rig.rate_hz
    y = integrate(rotor, sweep, t)
    x, z = y[0], y[1]
    phi = sweep.phi(t)
    cols: dict[str, np.ndarray] = {}
    for p in rig.probes:
        th = math.radians(p.angle_deg)
        d = x * math.cos(th) + z * math.sin(th)
        r1, r2 = rig.runout_vectors(p)
        run = (r1 * np.exp(1j * phi)).real + (r2 * np.exp(2j * phi)).real
        v = p.v_dc + p.sensitivity * (d + run) + rig.noise_v * rng.standard_normal(n)
        cols[p.column] = quantise(v, rig)
    events = sweep.event_times()
    kp = np.full(n, rig.kp_baseline_v)
    if keyphasor:
        # notch from each event (phi = 2 pi k) to phi = 2 pi k + width, edges smoothed by a
        # Gaussian of std kp_edge_s: -D/2 [erf((t - tf)/(sqrt2 s)) - erf((t - tr)/(sqrt2 s))]
        width = math.radians(rig.kp_width_deg)
        first, last = sweep.revolutions()
        ns = 2 * math.pi * np.arange(first - 1, last + 2)  # one notch more at each end
        falls, rises = sweep.time_at(ns), sweep.time_at(ns + width)
        s = rig.kp_edge_s * math.sqrt(2.0)
        reach = 8 * rig.kp_edge_s
        for tf, tr in zip(falls, rises):
            if not (np.isfinite(tf) and np.isfinite(tr)):
                continue
            i0 = max(0, int(math.floor((tf - reach) * rig.rate_hz)))
            i1 = min(n, int(math.ceil((tr + reach) * rig.rate_hz)) + 1)
            if i1 <= i0:
                continue
            tt = t[i0:i1]
            kp[i0:i1] -= 0.5 * rig.kp_depth_v * (erf((tt - tf) / s) - erf((tt - tr) / s))
    kp = kp + rig.kp_noise_v * rng.standard_normal(n)
    cols[rig.kp_column] = quantise(kp, rig)
    return Record(t, cols, phi, sweep.w(t), x, z, events, sweep, rig, time.perf_counter() - t0)


def scenario_toml(rig: Rig, slow_roll: str | None, probes: tuple[Probe, ...] | None = None) -> str:
    """The text of a scenario file holding only [acquisition] (docs/acquisition.md section
    8): time column t, the probes (column, angle_deg [deg], sensitivity [V/m]), the
    keyphasor (falling edge, threshold auto, angle_deg 0: phi = 0 at the event) and, when
    slow_roll names a file (relative to the scenario), [acquisition.runout] slow_roll."""
    probes = rig.probes if probes is None else probes
    lines = [
        "# Generated by crates/rotorid-py/tests/transient_rig.py: a rig's acquisition only",
        "# (no [rotor], [speed] or [sampling]: `rotorid transient` needs no model). SI units.",
        "[acquisition]",
        'time = "t"',
        "",
    ]
    for p in probes:
        lines += [
            "[[acquisition.probe]]",
            f'column = "{p.column}"',
            f"angle_deg = {p.angle_deg:.1f}",
            f"sensitivity = {p.sensitivity:.1f}          # V/m",
            "",
        ]
    lines += [
        "[acquisition.keyphasor]",
        f'column = "{rig.kp_column}"',
        'edge = "falling"',
        'threshold = "auto"',
        "angle_deg = 0.0",
        "",
    ]
    if slow_roll is not None:
        lines += ["[acquisition.runout]", f'slow_roll = "{slow_roll}"', ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- reference


@dataclass
class Peak:
    """One resonance peak of a steady-state amplitude curve: rpm [rpm], amplitude [m,
    0-pk], phase_lag_deg [deg, 0..360], n1_rpm, n2_rpm [rpm] (half-power speeds: the
    amplitude is peak / sqrt 2 there), af = rpm / (n2 - n1) [-]."""

    rpm: float
    amplitude: float
    phase_lag_deg: float
    n1_rpm: float
    n2_rpm: float

    @property
    def af(self) -> float:
        """API 684 amplification factor Nc / (N2 - N1) [-]."""
        return self.rpm / (self.n2_rpm - self.n1_rpm)


def peaks_of(amp, rpm_lo: float, rpm_hi: float, grid: int = 20001) -> list[tuple[float, float, float, float]]:
    """Local maxima of amp(rpm) [any unit, callable on an rpm array] on [rpm_lo, rpm_hi]
    with their half-power speeds: list of (rpm, amplitude, n1_rpm, n2_rpm) [rpm, unit].
    Each maximum is refined (bounded scalar minimisation), N1 and N2 found by brentq on
    amp - peak / sqrt 2 between the peak and the neighbouring minimum (or the range's end);
    NaN when the curve does not fall that far there."""
    r = np.linspace(rpm_lo, rpm_hi, grid)
    a = amp(r)
    imax = [i for i in range(1, grid - 1) if a[i] >= a[i - 1] and a[i] > a[i + 1]]
    imin = [0] + [i for i in range(1, grid - 1) if a[i] <= a[i - 1] and a[i] < a[i + 1]] + [grid - 1]
    out = []
    for i in imax:
        res = optimize.minimize_scalar(
            lambda q: -float(amp(np.array([q]))[0]), bounds=(r[i - 1], r[i + 1]), method="bounded",
            options={"xatol": 1e-9},
        )
        rp, ap = float(res.x), -float(res.fun)
        lo = max(j for j in imin if j < i)
        hi = min(j for j in imin if j > i)
        half = ap / math.sqrt(2)

        def f(q):
            return float(amp(np.array([q]))[0]) - half

        n1 = optimize.brentq(f, r[lo], rp, xtol=1e-9) if f(r[lo]) < 0 else float("nan")
        n2 = optimize.brentq(f, rp, r[hi], xtol=1e-9) if f(r[hi]) < 0 else float("nan")
        out.append((rp, ap, n1, n2))
    return out


def reference(rotor: Rotor, rig: Rig, rpm_lo: float, rpm_hi: float) -> dict:
    """The closed-form steady-state reference on [rpm_lo, rpm_hi] [rpm]:

    - ``modes``: [(natural speed sqrt(k/m) [rpm], damping ratio [-])] of the x and z modes;
    - ``peaks``: {probe column: [Peak, ...]} the steady-state 1X amplitude curve's maxima
      (runout excluded), in rising speed, with N1, N2 and AF;
    - ``vector``: {probe column: callable rpm -> complex steady-state 1X vector [m]};
    - ``runout``: {probe column: (1X, 2X) runout vectors [m, complex]}.
    """
    out: dict = {
        "modes": [(rotor.wx / RPM, rotor.zeta_x), (rotor.wz / RPM, rotor.zeta_z)],
        "peaks": {},
        "vector": {},
        "runout": {},
    }
    for p in rig.probes:
        def vec(rpm, _p=p):
            return steady_state_probe(rotor, np.asarray(rpm, dtype=float) * RPM, _p.angle_deg)

        pk = []
        for rp, ap, n1, n2 in peaks_of(lambda q, _v=vec: np.abs(_v(q)), rpm_lo, rpm_hi):
            lag = (-math.degrees(np.angle(vec(rp)))) % 360.0
            pk.append(Peak(rp, ap, lag, n1, n2))
        out["peaks"][p.column] = pk
        out["vector"][p.column] = vec
        out["runout"][p.column] = rig.runout_vectors(p)
    return out


def api684_margin(nc_rpm: float, af: float, op_min: float, op_max: float) -> tuple[float, float, bool]:
    """API 684 separation margin of a critical at nc_rpm [rpm] with amplification factor
    af [-] from the operating range [op_min, op_max] [rpm]: (actual %, required %, met).
    Below the range: actual = (MIN - Nc)/MIN 100, required = 0 if AF < 2.5 else
    min(16, 17 (1 - 1/(AF - 1.5))); above: actual = (Nc - MAX)/MAX 100, required =
    0 if AF < 2.5 else min(26, 10 + 17 (1 - 1/(AF - 1.5)))."""
    if nc_rpm <= op_min:
        actual = (op_min - nc_rpm) / op_min * 100.0
        required = 0.0 if af < 2.5 else min(16.0, 17.0 * (1.0 - 1.0 / (af - 1.5)))
    elif nc_rpm >= op_max:
        actual = (nc_rpm - op_max) / op_max * 100.0
        required = 0.0 if af < 2.5 else min(26.0, 10.0 + 17.0 * (1.0 - 1.0 / (af - 1.5)))
    else:
        raise ValueError(f"critical at {nc_rpm} rpm inside the operating range {op_min}..{op_max}")
    return actual, required, actual >= required


def ideal_tracking(rec: Record, probe: Probe) -> tuple[np.ndarray, np.ndarray]:
    """What a perfect order tracker gives on the noise-free motion (no runout, the true
    phi): per whole revolution between two keyphasor events, the 1X vector
    (1/pi) integral d(phi) e^{-i phi} dphi (trapezoid in phi over the samples, each end
    interpolated to the event) of the probe's displacement d = x cos th + z sin th.
    Returns (speed [rpm] = 60 / revolution time, vector [m, complex]), one per revolution.
    This is the transient 1X a run-up really has; its difference from the steady state is
    the sweep's own effect (lag, apparent-peak shift), which no tracker removes."""
    th = math.radians(probe.angle_deg)
    d = rec.x * math.cos(th) + rec.z * math.sin(th)
    ev = rec.events[rec.events <= rec.t[-1]]
    idx = np.searchsorted(rec.t, ev)  # first sample at or after each event
    speeds, vecs = [], []
    for k in range(len(ev) - 1):
        i0, i1 = idx[k], idx[k + 1]
        tt = np.concatenate([[ev[k]], rec.t[i0:i1], [ev[k + 1]]])
        dd = np.interp(tt, rec.t, d)
        pp = rec.sweep.phi(tt)
        g = dd * np.exp(-1j * pp)
        vecs.append(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(pp)) / math.pi)
        speeds.append(60.0 / (ev[k + 1] - ev[k]))
    return np.array(speeds), np.array(vecs)


def tracked_peaks(speed_rpm: np.ndarray, amp: np.ndarray, near_rpm: list[float], halfwidth: float = 0.06):
    """Peak speed, amplitude, N1, N2 [rpm, m, rpm, rpm] of a tracked (per-revolution)
    amplitude curve near each of near_rpm [rpm] (within +-halfwidth of it): the maximum
    sample refined by a parabola through its neighbours; N1, N2 the linearly interpolated
    crossings of peak / sqrt 2 nearest the peak."""
    order = np.argsort(speed_rpm)
    s, a = speed_rpm[order], amp[order]
    out = []
    for nr in near_rpm:
        sel = np.where(np.abs(s / nr - 1) < halfwidth)[0]
        i = sel[np.argmax(a[sel])]
        y0, y1, y2 = a[i - 1], a[i], a[i + 1]
        den = y0 - 2 * y1 + y2
        u = 0.5 * (y0 - y2) / den if den != 0 else 0.0
        rp = s[i] + u * 0.5 * (s[i + 1] - s[i - 1])
        ap = y1 - 0.25 * (y0 - y2) * u
        half = ap / math.sqrt(2)
        j = i
        while a[j] > half:
            j -= 1
        n1 = s[j] + (half - a[j]) / (a[j + 1] - a[j]) * (s[j + 1] - s[j])
        j = i
        while a[j] > half:
            j += 1
        n2 = s[j - 1] + (half - a[j - 1]) / (a[j] - a[j - 1]) * (s[j] - s[j - 1])
        out.append((rp, ap, n1, n2))
    return out


# --------------------------------------------------------------------------- the standard set


ROTOR = Rotor()
RIG = Rig()
RPM_SLOW = 480.0  # rpm: the slow roll and the run-up's start
RPM_TOP = 8400.0  # rpm: the run-up's end, the coast-down's start
ACCEL = 25.0  # rad/s^2
SLOW_ROLL_S = 3.0  # s
RPM_NOKP = 3000.0  # rpm: the record without keyphasor pulses (constant speed)
NOKP_S = 2.0  # s
RUNUP = Sweep(RPM_SLOW, RPM_TOP, ACCEL, phi0=1.0)
COASTDOWN = Sweep(RPM_TOP, RPM_SLOW, ACCEL, phi0=2.0)
SLOW_ROLL = Sweep(RPM_SLOW, RPM_SLOW, 0.0, SLOW_ROLL_S, phi0=0.5)
NOKP = Sweep(RPM_NOKP, RPM_NOKP, 0.0, NOKP_S, phi0=0.0)
SWEEPS = {"runup": RUNUP, "coastdown": COASTDOWN, "slowroll": SLOW_ROLL, "nokp": NOKP}
SEEDS = {"runup": 1, "coastdown": 2, "slowroll": 3, "nokp": 4}


def write_record(name: str, path: Path, rotor: Rotor = ROTOR, rig: Rig = RIG) -> Record:
    """Generate the standard record ``name`` (runup, coastdown, slowroll or nokp: the last
    without keyphasor pulses) with its seed and write it as CSV to path. Returns the record
    (its ``seconds``: the generation time [s])."""
    rec = make_record(rotor, rig, SWEEPS[name], SEEDS[name], keyphasor=(name != "nokp"))
    rec.write_csv(path)
    return rec


def kp_timing_error(rec: Record) -> float:
    """The keyphasor as a trigger would time it: the crossings of the notch's mid level
    (baseline - depth / 2) going down, linearly interpolated between samples, against the
    true event times (phi = 2 pi n). Returns the largest difference [s] (NaN if the counts
    differ). The first event is skipped when the record starts inside its edge."""
    rig = rec.rig
    v = rec.columns[rig.kp_column]
    th = rig.kp_baseline_v - 0.5 * rig.kp_depth_v
    i = np.where((v[:-1] >= th) & (v[1:] < th))[0]
    tc = rec.t[i] + (v[i] - th) / (v[i] - v[i + 1]) / rig.rate_hz
    ev = rec.events[rec.events > 4 * rig.kp_edge_s]
    tc = tc[tc > 4 * rig.kp_edge_s]
    if len(tc) != len(ev):
        return float("nan")
    return float(np.abs(tc - ev).max())


# --------------------------------------------------------------------------- self-test


def self_test(rotor: Rotor = ROTOR, rpm: float = 6000.0, seconds: float = 2.0) -> float:
    """Check the integration against the closed form at a constant speed rpm [rpm]:
    (1) the same right-hand side started from the steady state of 0.9 times the speed, so a
    free transient exists and must die out: after ``seconds`` [s] (the slower decay,
    exp(-zeta_x wx t), leaves 2e-14 after 2 s) the motion must equal Re(X e^{i phi}),
    Re(Z e^{i phi}); (2) ``integrate`` itself, started from its steady state, must stay on
    it. Returns the largest error relative to the steady amplitude [-]; raises
    AssertionError above 1e-8."""
    w = rpm * RPM
    sweep = Sweep(rpm, rpm, 0.0, seconds)
    X0, Z0 = steady_state_xz(rotor, 0.9 * w)
    m, kx, kz, cx, cz = rotor.m, rotor.kx, rotor.kz, rotor.cx, rotor.cz

    def rhs(tt, y):
        fx, fz = unbalance_force(rotor, w * tt, w, 0.0)
        return [y[2], y[3], (fx - cx * y[2] - kx * y[0]) / m, (fz - cz * y[3] - kz * y[1]) / m]

    t = np.linspace(seconds - 0.05, seconds, 501)
    sol = solve_ivp(rhs, (0, seconds), [X0.real, Z0.real, 0.0, 0.0], method="DOP853", rtol=RTOL, atol=ATOL, t_eval=t)
    X, Z = steady_state_xz(rotor, w)
    ex = np.abs(sol.y[0] - (X * np.exp(1j * w * t)).real).max() / abs(X)
    ez = np.abs(sol.y[1] - (Z * np.exp(1j * w * t)).real).max() / abs(Z)
    # and integrate() itself from its steady start: must stay on the steady state
    y = integrate(rotor, sweep, t)
    ex2 = np.abs(y[0] - (X * np.exp(1j * w * t)).real).max() / abs(X)
    ez2 = np.abs(y[1] - (Z * np.exp(1j * w * t)).real).max() / abs(Z)
    err = max(ex, ez, ex2, ez2)
    assert err < 1e-8, f"integrator off the closed form by {err:.3e} of the amplitude"
    return err


def main() -> None:  # pragma: no cover - a report for people
    import tempfile

    rep = reference(ROTOR, RIG, RPM_SLOW, RPM_TOP)
    print("rotor:", ROTOR)
    print(f"  cx = {ROTOR.cx:.2f} N s/m, cz = {ROTOR.cz:.2f} N s/m, e = m_u d / m = {ROTOR.mud / ROTOR.m * 1e6:.3f} um")
    for i, (n, zeta) in enumerate(rep["modes"]):
        print(f"  mode {'xz'[i]}: natural speed {n:.2f} rpm, damping ratio {zeta}, AF 1/(2 zeta) = {1 / (2 * zeta):.2f}")
    t0 = time.perf_counter()
    err = self_test()
    print(f"self-test: integrator vs closed form at 6000 rpm: {err:.2e} of the amplitude ({time.perf_counter() - t0:.1f} s)")
    for p in RIG.probes:
        r1, r2 = rep["runout"][p.column]
        print(f"{p.column} ({p.angle_deg} deg): runout 1X {abs(r1) * 1e6:.2f} um @ {np.degrees(np.angle(r1)):.1f} deg, "
              f"2X {abs(r2) * 1e6:.2f} um @ {np.degrees(np.angle(r2)):.1f} deg")
        for k in rep["peaks"][p.column]:
            print(f"  steady-state peak {k.rpm:.2f} rpm, {k.amplitude * 1e6:.3f} um 0-pk, lag {k.phase_lag_deg:.1f} deg, "
                  f"N1 {k.n1_rpm:.2f}, N2 {k.n2_rpm:.2f}, AF {k.af:.3f}")
    with tempfile.TemporaryDirectory() as d:
        for name in ("runup", "coastdown", "slowroll"):
            sweep = SWEEPS[name]
            path = Path(d) / f"{name}.csv"
            rec = write_record(name, path)
            print(f"{name}: {sweep.rpm_from:.0f} -> {sweep.rpm_to:.0f} rpm at {sweep.a:+.1f} rad/s^2, {sweep.duration:.2f} s, "
                  f"{len(rec.t)} samples, {len(rec.events)} keyphasor events, generated in {rec.seconds:.1f} s, "
                  f"CSV {path.stat().st_size / 1e6:.2f} MB; keyphasor timing error {kp_timing_error(rec) * 1e6:.2f} us")
            if name == "slowroll":
                continue
            for p in RIG.probes:
                s, v = ideal_tracking(rec, p)
                pk = rep["peaks"][p.column]
                tp = tracked_peaks(s, np.abs(v), [k.rpm for k in pk])
                ref = np.abs(rep["vector"][p.column](s))
                big = max(k.amplitude for k in pk)
                rms = math.sqrt(np.mean((np.abs(v) - ref) ** 2)) / big
                crms = math.sqrt(np.mean(np.abs(v - rep["vector"][p.column](s)) ** 2)) / big
                print(f"  {p.column}: ideal tracker (noise-free, true phi): {len(s)} revolutions, amplitude RMS error "
                      f"{rms * 100:.2f} % of the peak, vector RMS error {crms * 100:.2f} %")
                for k, (rp, ap, n1, n2) in zip(pk, tp):
                    af = rp / (n2 - n1)
                    print(f"    apparent peak {rp:.1f} rpm ({(rp / k.rpm - 1) * 100:+.2f} % from steady state), "
                          f"{ap * 1e6:.2f} um ({(ap / k.amplitude - 1) * 100:+.2f} %), AF {af:.2f} ({(af / k.af - 1) * 100:+.1f} %)")


if __name__ == "__main__":  # pragma: no cover
    main()
