"""The extension module (Rust). Use the package ``rotorid``; these are its building blocks."""

import os
from typing import Any, final

import numpy as np

from . import Scenario as Scenario

__all__ = ["ESTIMATE_COLUMNS", "ESTIMATE_COLUMNS_BY_MODEL", "METHODS", "MODELS", "UNKNOWNS", "Blocks", "Scenario", "Session", "balance", "identify", "identify_finite_element", "load_finite_element", "read", "read_blocks", "read_fe_matrices", "simulate", "transient"]

METHODS: list[str]
MODELS: list[str]
UNKNOWNS: list[str]
ESTIMATE_COLUMNS: list[str]
ESTIMATE_COLUMNS_BY_MODEL: dict[str, list[str]]

def simulate(
    scenario: Scenario,
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
) -> dict[str, np.ndarray]: ...
def read(path: str, columns: str | None = None) -> tuple[dict[str, np.ndarray], dict[str, str]]: ...
def read_blocks(path: str, columns: str | None = None, rows: int = 65536) -> Blocks: ...
def read_fe_matrices(path: str) -> dict[str, Any]: ...
def load_finite_element(path: str) -> dict[str, Any]: ...
def identify_finite_element(
    t: list[float],
    channels: list[tuple[str, list[float]]],
    scenario: str,
    unknowns: str | None = None,
    initial: str | None = None,
    modes: int | None = None,
    offsets: bool = False,
) -> str: ...
@final
class Blocks:
    @property
    def units(self) -> dict[str, str]: ...
    def __iter__(self) -> Blocks: ...
    def __next__(self) -> tuple[int, dict[str, np.ndarray]]: ...
def identify(
    scenario: Scenario,
    method: str,
    t: Any,
    x: Any,
    z: Any,
    phi: Any = None,
    phi_dot: Any = None,
    phi_ddot: Any = None,
    *,
    model: str | None = None,
    unknowns: list[str] | None = None,
    quadrature: str | None = None,
    rcond_min: float | None = None,
    tol: float | None = None,
    window: float | None = None,
    restart: float | None = None,
    time_tolerance: float = ...,
    input: str | None = None,
    scenario_name: str | None = None,
) -> tuple[str, dict[str, np.ndarray], float]:
    """(summary JSON, estimates columns, seconds spent in the library)."""

def balance(
    vectors: str,
    masses: str,
    current: str,
    *,
    vectors_name: str = "vectors",
    masses_name: str = "masses",
    method: str = "ls",
    speeds: list[float] | None = None,
    planes: list[str] | None = None,
    limits: list[tuple[str, float]] = ...,
    weights: list[tuple[str, float]] = ...,
    radius: list[tuple[str, float]] = ...,
    default_radius: float | None = None,
    holes_equal: list[tuple[str, tuple[int, float]]] = ...,
    holes_angles: list[tuple[str, list[float]]] = ...,
    mass_set: list[float] | None = None,
    per_hole: int = 1,
    phase: str | None = None,
    unit: str | None = None,
    plan: float | None = None,
) -> str:
    """balance.json (or, with plan=fraction, the trial plan) as JSON text."""

def transient(
    records: list[str],
    *,
    scenario: Scenario | str | os.PathLike[str] | None = None,
    vectors: str | None = None,
    vectors_name: str | None = None,
    amplitude: str = "pk",
    unit: str | None = None,
    slow_roll_kind: str = "default",
    slow_roll_file: str | None = None,
    slow_roll_range: tuple[float, float] | None = None,
    orders: list[int] | None = None,
    operating_rpm: tuple[float, float] | None = None,
    bin_rpm: float | None = None,
) -> tuple[str, dict[str, Any], list[tuple[str, str]]]:
    """(transient.json text, bode.csv columns, [(file, reader note)])."""

@final
class Session:
    def __new__(
        cls,
        scenario: Scenario,
        method: str = "algebraic",
        dt: float | None = None,
        t0: float = 0.0,
        *,
        model: str | None = None,
        unknowns: list[str] | None = None,
        quadrature: str | None = None,
        rcond_min: float | None = None,
        tol: float | None = None,
        window: float | None = None,
        restart: float | None = None,
        time_tolerance: float = ...,
    ) -> Session: ...
    @property
    def samples(self) -> int: ...
    def push(
        self, x: Any, z: Any, t: Any = None, phi: Any = None, phi_dot: Any = None, phi_ddot: Any = None
    ) -> dict[str, np.ndarray]: ...
    def start_now(self) -> dict[str, np.ndarray]: ...
    def finish(
        self, *, input: str | None = None, scenario_name: str | None = None
    ) -> tuple[str, dict[str, np.ndarray]]: ...
