"""Type stubs of rotorid (SI units throughout; see the docstrings)."""

import dataclasses
import os
from typing import Any, Iterator, Mapping, Sequence, final

import numpy as np
import pandas as pd

from ._balance import Balance as Balance
from ._balance import TrialPlan as TrialPlan
from ._balance import balance as balance
from ._balance import plan_trials as plan_trials
from ._result import Identification as Identification
from ._transient import Transient as Transient
from ._transient import transient as transient

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

__version__: str
METHODS: list[str]
MODELS: list[str]
UNKNOWNS: list[str]
ESTIMATE_COLUMNS: list[str]
ESTIMATE_COLUMNS_BY_MODEL: dict[str, list[str]]

@final
class Scenario:
    """A scenario: the built-in table1, a TOML file, or the file's keys as keyword
    arguments: model (``"jeffcott"``, the default, or ``"cross_coupled"``), m [kg]; the
    Jeffcott model's cx, cz [N s/m], kx, kz [N/m] or the cross-coupled model's kxx, kxz,
    kzx, kzz [N/m], cxx, cxz, czx, czz [N s/m]; a [N s^2/m], m_u [kg], d [m], alpha_deg
    [deg]; rpm [rev/min] (constant speed) or rpm0 [rev/min] and accel [rad/s^2] (ramp),
    phi0_deg [deg]; dt, duration [s]; x0, z0 [m], vx0, vz0 [m/s]. Out-of-range values (a
    damping matrix that is not dissipative, a key of the other model) raise ValueError
    naming the key and its allowed range."""

    def __new__(
        cls,
        *,
        model: str | None = None,
        m: float | None = None,
        cx: float | None = None,
        kx: float | None = None,
        cz: float | None = None,
        kz: float | None = None,
        kxx: float | None = None,
        kxz: float | None = None,
        kzx: float | None = None,
        kzz: float | None = None,
        cxx: float | None = None,
        cxz: float | None = None,
        czx: float | None = None,
        czz: float | None = None,
        a: float | None = None,
        m_u: float | None = None,
        d: float | None = None,
        alpha_deg: float | None = None,
        rpm: float | None = None,
        rpm0: float | None = None,
        accel: float | None = None,
        phi0_deg: float | None = None,
        dt: float | None = None,
        duration: float | None = None,
        x0: float | None = None,
        z0: float | None = None,
        vx0: float | None = None,
        vz0: float | None = None,
    ) -> Scenario: ...
    @staticmethod
    def table1() -> Scenario:
        """The paper's Table 1 rotor at 1200 rpm, dt = 0.1 ms, 1 s, from rest."""
    @staticmethod
    def from_toml(path: str | os.PathLike[str]) -> Scenario:
        """A TOML scenario file (errors name file, line, key and allowed range)."""
    @staticmethod
    def load(arg: str) -> Scenario:
        """``"table1"`` or a TOML path, as the CLI's ``--scenario``."""
    @property
    def origin(self) -> str:
        """``table1``, the file's path, or ``Scenario()``."""
    def to_dict(self) -> dict[str, float | str]:
        """The keys it states, ``model`` first (keyword arguments of an equal scenario)."""

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
    """t [s], x, z [m], phi [rad], phi_dot [rad/s], phi_ddot [rad/s^2]."""

def read(path: str | os.PathLike[str], columns: str | None = None) -> pd.DataFrame:
    """A response CSV as the CLI reads it."""

def read_blocks(
    path: str | os.PathLike[str], columns: str | None = None, rows: int = 65536
) -> Iterator[pd.DataFrame]:
    """The record :func:`read` reads, ``rows`` rows at a time (TDMS and Parquet streamed)."""

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
    """Identify one record (see the docstring)."""

class Session:
    """A live identification."""

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
    ) -> None: ...
    @property
    def samples(self) -> int: ...
    def push(
        self,
        x: np.ndarray | Sequence[float],
        z: np.ndarray | Sequence[float],
        *,
        t: np.ndarray | Sequence[float] | None = None,
        phi: np.ndarray | Sequence[float] | None = None,
        phi_dot: np.ndarray | Sequence[float] | None = None,
        phi_ddot: np.ndarray | Sequence[float] | None = None,
    ) -> pd.DataFrame: ...
    def start_now(self) -> pd.DataFrame: ...
    def finish(self, *, input: str | None = None, scenario: str | None = None) -> Identification: ...

@dataclasses.dataclass(frozen=True)
class FiniteElementRotor:
    matrices: str
    dofs: list[str]
    M: np.ndarray
    K: np.ndarray
    G: np.ndarray
    C: np.ndarray | None
    Ka: np.ndarray | None
    bearings: list[dict[str, float]]
    unbalances: list[dict[str, float]]

def load_finite_element(scenario: str | os.PathLike[str]) -> FiniteElementRotor: ...
def identify_finite_element(
    data: pd.DataFrame | Mapping[str, Any],
    scenario: str | os.PathLike[str],
    *,
    unknowns: str | Sequence[str] | None = None,
    initial: str = "estimated",
    modes: int | None = None,
    offsets: bool = False,
) -> dict[str, Any]: ...
