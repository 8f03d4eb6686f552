"""rotorid: identify the physical parameters of a 2-DOF rotor from vibration.

Two models (``docs/method.md`` sections 1.2 and 1.6, SI units throughout). The paper's
Jeffcott rotor, eq. (1)::

    m x'' + cx x' - a w z' - a w' z + kx x = m_u d (w^2 sin(phi+alpha) - w' cos(phi+alpha))
    m z'' + cz z' + a w x'          + kz z = m_u d (w' sin(phi+alpha) + w^2 cos(phi+alpha))

and the same disk on cross-coupled bearings (``model="cross_coupled"``), whose stiffness and
damping are full 2x2 matrices::

    m x'' + cxx x' + cxz z' - a w z' + kxx x + kxz z - a w' z = Fx
    m z'' + czx x' + czz z' + a w x' + kzx x + kzz z          = Fz

with x horizontal and z vertical displacement [m], phi the rotor angle [rad] (the shaft
turns from +z towards +x), w = phi' [rad/s], m [kg], c [N s/m], k [N/m] (kxz: the restoring
force in x per unit displacement in z), a [N s^2/m], m_u d [kg m], alpha [rad].

Quick start::

    import rotorid
    sc = rotorid.Scenario.table1()
    df = rotorid.simulate(sc, snr_db=40, seed=1)      # t, x, z, phi, phi_dot, phi_ddot
    res = rotorid.identify(df, sc, method="refine")    # model="cross_coupled" or "auto"
    res.params                                         # value, std_error, crb, unit, ...

Every computation runs in the Rust library with the GIL released; a record gives the
same result (``res.to_dict()``) as ``rotorid identify --summary`` on the same file.

Balancing (influence coefficients of many planes, sensors and speeds)::

    b = rotorid.balance(vectors_df, masses_df, current="asfound", holes={"disk1": 12})
    b.corrections                                      # mass_kg, angle_deg and their std
    b.residual, b.influence, b.split                   # DataFrames; b.to_dict() == balance.json

Run-ups and coast-downs (``docs/transient.md``), as ``rotorid transient`` analyses them::

    tr = rotorid.transient("runup.csv", scenario="rig.toml", operating_rpm=(3000, 3600))
    tr.bode, tr.criticals                              # DataFrames; tr.to_dict() == transient.json
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import Any, Iterator, Mapping, Sequence

import numpy as np
import pandas as pd

from . import _rotorid
from ._rotorid import (
    ESTIMATE_COLUMNS,
    ESTIMATE_COLUMNS_BY_MODEL,
    METHODS,
    MODELS,
    UNKNOWNS,
    Scenario,
)
from ._balance import Balance, TrialPlan, balance, plan_trials
from ._result import Identification
from ._transient import Transient, transient

__all__ = [
    "ESTIMATE_COLUMNS",
    "ESTIMATE_COLUMNS_BY_MODEL",
    "METHODS",
    "MODELS",
    "UNKNOWNS",
    "Balance",
    "FiniteElementRotor",
    "Identification",
    "Scenario",
    "Session",
    "TrialPlan",
    "Transient",
    "balance",
    "identify",
    "load_finite_element",
    "identify_finite_element",
    "plan_trials",
    "read",
    "read_blocks",
    "simulate",
    "transient",
]

__version__ = "0.1.0"

_SPEED = ("phi", "phi_dot", "phi_ddot")


def _scenario(sc: Scenario | str | os.PathLike[str]) -> Scenario:
    if isinstance(sc, Scenario):
        return sc
    if isinstance(sc, (str, os.PathLike)):
        return Scenario.load(os.fspath(sc))
    raise TypeError(f"scenario: expected a rotorid.Scenario, 'table1' or a path, got {type(sc).__name__}")


@dataclasses.dataclass(frozen=True)
class FiniteElementRotor:
    """A finite-element rotor as rotorid loads it (``docs/formats.md``): the shaft and disks
    as matrices, one row and column per degree of freedom ``dofs`` (``<node>.<dof>``, dof
    one of x, y [m], rx, ry [rad]), and the bearings and unbalances of its scenario.

    Attributes:
        matrices: the path of the matrices file read (relative to the scenario's directory).
        dofs: the names of the rows and columns.
        M: mass [kg, kg m, kg m^2]; K: stiffness of the shaft and disks, no bearings [N/m,
            N, N m/rad]; G: gyroscopic, multiplied by phi' [kg, kg m, kg m^2]; each n x n.
        C: shaft damping [N s/m, ...], or None; Ka: the matrix multiplied by phi'' (ROSS's
            Ksdt), or None.
        bearings: per ``[[rotor.bearing]]`` (bearing0, ...): node, kxx, kxy, kyx, kyy [N/m],
            cxx, cxy, cyx, cyy [N s/m].
        unbalances: per ``[[rotor.unbalance]]`` (unbalance0, ...): node, mud [kg m], alpha
            [rad] (its angle at phi = 0 from +x towards +y).
    """

    matrices: str
    dofs: list[str]
    M: np.ndarray
    K: np.ndarray
    G: np.ndarray
    C: np.ndarray | None
    Ka: np.ndarray | None
    bearings: list[dict[str, float]]
    unbalances: list[dict[str, float]]


def load_finite_element(scenario: str | os.PathLike[str]) -> FiniteElementRotor:
    """Load the finite-element rotor of a scenario TOML (``rotor.model =
    "finite_element"``): its matrices file (``rotor.matrices``, relative to the scenario)
    read and checked (members, shapes, dtypes; dof names; M symmetric and positive
    definite; every entry finite) and its bearings and unbalances checked and placed on
    it, as the ``rotorid`` command loads it. Raises ``ValueError`` naming the file, the
    line or member and what is allowed, ``FileNotFoundError`` for a missing file."""
    return FiniteElementRotor(**_rotorid.load_finite_element(os.fspath(scenario)))


def identify_finite_element(
    data: Any,
    scenario: str | os.PathLike[str],
    *,
    unknowns: str | Sequence[str] | None = None,
    initial: str = "estimated",
    modes: int | None = None,
    offsets: bool = False,
) -> dict[str, Any]:
    """Identify the bearings and unbalances of a finite-element rotor, as ``rotorid
    identify DATA --scenario S.toml --method refine`` does (docs/finite_element.md
    section 5): maximum likelihood on the reduced model, started from the scenario's
    values of the unknowns (the others known).

    Args:
        data: a DataFrame or a mapping of 1-D arrays: ``t`` [s] (uniform) and one column
            per measured degree of freedom named ``<node>.<dof>`` (m or rad), e.g.
            ``0.x``; ``phi``, ``phi_dot``, ``phi_ddot`` are ignored (the speed is the
            scenario's ``[speed]`` profile from the first sample).
        scenario: the scenario TOML (``rotor.model = "finite_element"``).
        unknowns: names or groups (``"bearings,unbalances"``, ``["bearing0.kxx",
            "unbalance1"]``); ``None``: every bearing's direct coefficients and every
            unbalance.
        initial: ``"rest"`` (the record starts at rest) or ``"estimated"``.
        modes: modes of the Ritz basis (``None``: 6).
        offsets: fit one constant offset per channel (data = response + offset + noise),
            for channels whose DC was removed (a mean or a gap voltage subtracted, as a
            conditioning without a rotor model does); reported under ``offsets``.

    Returns the summary as a dict (docs/summary.md, "Finite-element rotors"): each
    unknown with its standard error under ``parameters``, the covariance, the rotor with
    the estimates in, the noise, the adequacy and the reduction's bias; it feeds
    :func:`rotorid.ross.update`. Raises ``ValueError`` naming the column, field or option
    and what is allowed.
    """
    if isinstance(data, pd.DataFrame):
        names = [str(c) for c in data.columns]
        get = lambda k: data[k].to_numpy()  # noqa: E731
    elif isinstance(data, Mapping):
        names = [str(c) for c in data.keys()]
        get = lambda k: data[k]  # noqa: E731
    else:
        raise TypeError(
            f"data: expected a pandas DataFrame or a dict of arrays, got {type(data).__name__}")
    if "t" not in names:
        raise ValueError(f"data: no column t (time, s); columns: {', '.join(names)}")
    skip = {"t", "phi", "phi_dot", "phi_ddot"}
    channels = [(k, np.asarray(get(k), dtype=np.float64).tolist()) for k in names if k not in skip]
    if not channels:
        raise ValueError("data: no measured degree of freedom (a column `<node>.<dof>`, e.g. 0.x)")
    if isinstance(unknowns, str) or unknowns is None:
        u = unknowns
    else:
        u = ",".join(unknowns)
    t = np.asarray(get("t"), dtype=np.float64).tolist()
    text = _rotorid.identify_finite_element(
        t, channels, os.fspath(scenario), u, initial, modes, bool(offsets))
    return json.loads(text)


def _frame(columns: Mapping[str, np.ndarray]) -> pd.DataFrame:
    # copy=False: each numpy array becomes its own column block, not copied into one.
    return pd.DataFrame(dict(columns), copy=False)


def simulate(
    sc: Scenario | str,
    method: str = "exact",
    snr_db: float | None = None,
    seed: int = 0,
    *,
    dt: float | None = None,
    duration: float | None = None,
    x0: float | None = None,
    z0: float | None = None,
    vx0: float | None = None,
    vz0: float | None = None,
) -> pd.DataFrame:
    """Simulate the scenario's rotor, as ``rotorid simulate`` does.

    Args:
        sc: the scenario (rotor, speed, sampling and initial state all needed).
        method: ``"exact"`` (exact discretisation at constant speed, DoPri8 otherwise,
            ~1e-10 of the signal) or ``"newmark"`` (the paper's integrator).
        snr_db: add white Gaussian noise to x and z at this signal-to-noise ratio [dB]
            (sigma = RMS of the channel * 10^(-snr_db/20)); ``None`` for none.
        seed: seed of the noise (the same seed gives the same noise as the CLI's ``--seed``).
        dt, duration: override the scenario's sampling period and length [s].
        x0, z0 [m], vx0, vz0 [m/s]: override the initial state.

    Returns:
        DataFrame with columns t [s], x, z [m], phi [rad], phi_dot [rad/s],
        phi_ddot [rad/s^2]; row i at t = i dt exactly.
    """
    cols = _rotorid.simulate(
        _scenario(sc), method, snr_db, seed,
        dt=dt, duration=duration, x0=x0, z0=z0, vx0=vx0, vz0=vz0,
    )
    return _frame(cols)


def read(path: str | os.PathLike[str], columns: str | None = None) -> pd.DataFrame:
    """Read a record as ``rotorid identify`` reads it: a response CSV, or a MATLAB .mat
    (v5 or v7.3), LabVIEW .tdms, UFF58 (.uff, .unv, .58), .npy, .npz or .parquet file,
    whose channels for t, x, z (and phi, phi_dot, phi_ddot) are the role names or those
    ``columns`` gives (``"rec.t,rec.x,rec.z"``, ``"g/x"``, ``"0,1,2"`` for a 2-D .npy; a
    struct field or TDMS channel alone when unique), with units from the file (TDMS
    ``unit_string``, UFF58 ordinate unit), as ``rotorid identify --columns`` reads them.

    The header names at least t, x, z (any order, extra columns ignored); phi, phi_dot,
    phi_ddot all three or none. Values are SI unless a column's header gives its unit
    (``t (ms)``, ``x [um]``, ``phi [deg]``, ``phi_dot [rpm]``, ``phi_ddot [rpm/s]``): those
    columns are converted to SI, as the CLI converts them. Accepted: t in s, ms, us; x, z
    in m, mm, um (µm), nm, mil, in; phi in rad, deg, rev; phi_dot in rad/s, rpm, Hz,
    deg/s; phi_ddot in rad/s^2, rpm/s, Hz/s, deg/s^2.

    Returns:
        DataFrame with columns t [s], x, z [m] and, when the file has them, phi [rad],
        phi_dot [rad/s], phi_ddot [rad/s^2], bit for bit the numbers the CLI reads.
        ``df.attrs["units"]`` maps each column the file gave in another unit to that
        unit as written (``{"x": "um", "z": "um"}``; empty for a file in SI).

    Warns:
        UserWarning: what the reader noted about the file that is not an error, naming
            it: a TDMS recording interrupted mid-segment, whose unfinished last chunk was
            not read (the whole chunks before it were).

    Raises:
        ValueError: naming the file, line and column of a field that is not a finite
            number, a missing column, a short row, or a unit that is unknown or not one
            of the column's quantity (listing the units it takes). OSError: the file
            cannot be read.
    """
    columns, units = _rotorid.read(os.fspath(path), columns)
    df = _frame(columns)
    df.attrs["units"] = dict(units)
    return df


def read_blocks(
    path: str | os.PathLike[str], columns: str | None = None, rows: int = 65536
) -> Iterator[pd.DataFrame]:
    """Read a record as :func:`read` does, ``rows`` rows at a time: for a recording too
    long to hold, fed block by block to a :class:`Session`.

    A LabVIEW .tdms or a .parquet file is streamed (TDMS segments, Parquet row groups and
    pages): memory holds a block, whatever the recording's length. Any other format is read
    whole, as :func:`read` reads it, then handed out a block at a time.

    The file is opened, and its channels checked, when this is called (an error is raised
    here, not at the first block); a fault found later in the file is raised by the block
    that reaches it, after every block before it.

    Returns:
        An iterator of DataFrames of at most ``rows`` rows: the columns of :func:`read`
        (t [s], x, z [m], and phi [rad], phi_dot [rad/s], phi_ddot [rad/s^2] when the file
        has them), bit for bit its numbers, indexed by sample number (the first block's
        index starts at 0), ``attrs["units"]`` as :func:`read` gives it.

    Warns:
        UserWarning: as :func:`read` (a TDMS recording interrupted mid-segment).

    Raises:
        ValueError: as :func:`read`, and ``rows`` < 1. OSError: the file cannot be read.
    """
    if isinstance(rows, bool) or not isinstance(rows, int) or rows < 1:
        raise ValueError(f"rows = {rows!r} is out of range: an integer >= 1 (rows per block)")
    blocks = _rotorid.read_blocks(os.fspath(path), columns, rows)
    units = dict(blocks.units)

    def frames() -> Iterator[pd.DataFrame]:
        for first, cols in blocks:
            df = _frame(cols)
            df.index = pd.RangeIndex(first, first + len(df))
            df.attrs["units"] = dict(units)
            yield df

    return frames()


def _columns(data: Any) -> dict[str, Any]:
    """t, x, z [, phi, phi_dot, phi_ddot] of a DataFrame or a mapping of arrays."""
    if isinstance(data, pd.DataFrame):
        names = set(data.columns)

        def get(k: str) -> Any:
            return data[k].to_numpy() if k in names else None
    elif isinstance(data, Mapping):
        def get(k: str) -> Any:
            return data.get(k)
    else:
        raise TypeError(
            f"data: expected a pandas DataFrame or a dict of arrays, got {type(data).__name__}"
        )
    out = {k: get(k) for k in ("t", "x", "z", *_SPEED)}
    missing = [k for k in ("t", "x", "z") if out[k] is None]
    if missing:
        raise ValueError(f"data: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)}: "
                         "give t [s], x, z [m] (and phi, phi_dot, phi_ddot, or a scenario with a speed profile)")
    return out


def identify(
    data: pd.DataFrame | Mapping[str, Any],
    sc: Scenario | str,
    method: str = "refine",
    unknowns: Sequence[str] | None = None,
    *,
    model: str | None = None,
    quadrature: str | None = None,
    rcond_min: float | None = None,
    tol: float | None = None,
    window: float | None = None,
    restart: float | None = None,
    time_tolerance: float = 1e-6,
    input: str | None = None,
    scenario: str | None = None,
) -> Identification:
    """Identify the rotor's parameters from one record.

    Args:
        data: DataFrame or dict of 1-D arrays: t [s], x, z [m] and optionally phi [rad],
            phi_dot [rad/s], phi_ddot [rad/s^2] (all three or none; without them the
            scenario's speed profile gives the speed). float64 contiguous arrays are read
            in place; other dtypes and layouts are converted.
        sc: what is known besides the record: a, m_u, d, alpha_deg (and the truth m, c, k
            when stated, for errors and the Cramer-Rao bound); ``"table1"`` or a TOML path
            are loaded. Its model (``rotor.model``) is the default model.
        method: ``"algebraic"`` (an estimate per sample), ``"modulating"`` (least squares
            over windows) or ``"refine"`` (maximum likelihood with standard errors and the
            Cramer-Rao bound).
        unknowns: refine: what to estimate among m, the model's coefficients (Jeffcott:
            cx, kx, cz, kz; cross-coupled: cxx, cxz, czx, czz, kxx, kxz, kzx, kzz), a,
            unbalance (default m and the model's coefficients); the others are known from
            the scenario.
        model: ``"jeffcott"``, ``"cross_coupled"`` (overrides the scenario's ``rotor.model``,
            as the CLI's ``--model``) or, with method refine, ``"auto"``: both are fitted
            and the simplest whose residuals pass the adequacy test is taken by BIC
            (``res.model``, ``res.model_selection``, ``res.notes``). Default: the
            scenario's.
        quadrature: algebraic (and refine's start): trapezoid, am3, am4, am5 (default am5).
        rcond_min: conditioning threshold in [0, 1] (default 1e-5 algebraic, 1e-8 modulating).
        tol: algebraic: relative band of the identification time (default 0.01).
        restart: algebraic: restart the integrals on overlapping windows of this period [s]
            (every estimate from a window between half and one period old; default: one
            identifier over the whole record).
        window: modulating and refine: window of the modulating identifier [s] (default 0.02).
        time_tolerance: allowed deviation of a stamp from the uniform grid fitted by least
            squares over the stamps, relative to that dt; stamps whose values have few
            decimals (printed to 6 decimals at 25.6 kHz) may besides be off by one unit of
            their last decimal (at most dt/4): accepted, with a note (``notes``).
        input, scenario: the names written into the summary (``to_dict()``), as the CLI
            writes its input path and ``--scenario`` argument; default None.

    Returns:
        The :class:`Identification`.

    Raises:
        ValueError: a bad option (naming it and its allowed range; ``model="auto"`` with
            another method than refine), a column that is not 1-D or holds NaN or
            infinity (naming it and the sample index), non-uniform sampling, or a
            scenario that lacks what the method needs.
    """
    cols = _columns(data)
    summary, estimates, seconds = _rotorid.identify(
        _scenario(sc), method, cols["t"], cols["x"], cols["z"],
        cols["phi"], cols["phi_dot"], cols["phi_ddot"], model=model,
        unknowns=None if unknowns is None else list(unknowns),
        quadrature=quadrature, rcond_min=rcond_min, tol=tol, window=window,
        restart=restart, time_tolerance=time_tolerance, input=input, scenario_name=scenario,
    )
    return Identification(summary, estimates, core_seconds=seconds)


class Session:
    """A live identification: push chunks of samples as they arrive.

    Args:
        sc: the scenario (its speed profile gives the speed of chunks without phi).
        method: ``"algebraic"`` (estimates as samples arrive), ``"modulating"`` or
            ``"refine"`` (one result at :meth:`finish`).
        dt: the sampling period [s]; chunks then need no ``t`` (stamps, when given, are
            checked against t0 + i dt). ``None``: the grid is fitted over the first 4096
            stamps, held back until then (or until :meth:`start_now`), as the CLI does.
        t0: time of the first sample [s] when ``dt`` is given.
        Other keyword arguments (``model``, ``unknowns``, ...): as :func:`identify`.

    Example::

        s = rotorid.Session(sc, method="algebraic", dt=1e-4)
        est = s.push(x_chunk, z_chunk, phi=phi_chunk)   # speed from the scenario's profile
        res = s.finish()
    """

    def __init__(
        self,
        sc: Scenario | str,
        method: str = "algebraic",
        dt: float | None = None,
        t0: float = 0.0,
        *,
        model: str | None = None,
        unknowns: Sequence[str] | None = None,
        quadrature: str | None = None,
        rcond_min: float | None = None,
        tol: float | None = None,
        window: float | None = None,
        restart: float | None = None,
        time_tolerance: float = 1e-6,
    ) -> None:
        self._inner = _rotorid.Session(
            _scenario(sc), method, dt, t0, model=model,
            unknowns=None if unknowns is None else list(unknowns),
            quadrature=quadrature, rcond_min=rcond_min, tol=tol, window=window,
            restart=restart, time_tolerance=time_tolerance,
        )
        self._chunks: list[dict[str, np.ndarray]] = []

    @property
    def samples(self) -> int:
        """Samples pushed so far."""
        return self._inner.samples

    def push(
        self,
        x: Any,
        z: Any,
        *,
        t: Any = None,
        phi: Any = None,
        phi_dot: Any = None,
        phi_ddot: Any = None,
    ) -> pd.DataFrame:
        """Push a chunk: x, z [m] (and t [s], phi [rad], phi_dot [rad/s], phi_ddot [rad/s^2]).

        phi, phi_dot, phi_ddot: all three, none (the scenario's speed profile gives them),
        or phi alone (a keyphasor's angle: speed and acceleration from the scenario's
        profile at each sample's time).
        An error (NaN, a stamp off the grid) names the sample's index in the stream; the
        samples before it are taken.

        Returns:
            DataFrame of the new algebraic estimates (columns as ``Identification.estimates``);
            empty for modulating and refine, and while a fitted grid's head is held back.
        """
        est = self._inner.push(x, z, t, phi, phi_dot, phi_ddot)
        self._chunks.append(est)
        return _frame(est)

    def start_now(self) -> pd.DataFrame:
        """Fit the grid over the stamps held back so far and return their estimates."""
        est = self._inner.start_now()
        self._chunks.append(est)
        return _frame(est)

    def finish(self, *, input: str | None = None, scenario: str | None = None) -> Identification:
        """The identification of every sample pushed; its ``estimates`` hold every row."""
        summary, rest = self._inner.finish(input=input, scenario_name=scenario)
        chunks = [*self._chunks, rest]
        # the chunks with rows are of one model (an algebraic stream's); a batch method's
        # one row may be of the model refine chose, its earlier chunks empty
        full = [c for c in chunks if len(c["t"])]
        names = list(full[0]) if full else list(rest)
        estimates = {
            k: np.concatenate([c[k] for c in full]) if full else rest[k] for k in names
        }
        self._chunks = []
        return Identification(summary, estimates)
