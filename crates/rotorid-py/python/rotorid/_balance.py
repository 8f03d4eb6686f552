"""Multi-plane balancing from Python: ``rotorid.balance`` and ``rotorid.plan_trials``.

Both take the two tables of ``rotorid balance`` (docs/balancing.md) as pandas DataFrames
or CSV paths: vectors ``run, speed_rpm, sensor, re, im`` (or ``amp, phase_deg`` with
``phase="lag"|"lead"``; optional ``unit``, ``re_std, im_std`` or ``std``) and masses
``run, plane, mass_kg, radius_m, angle_deg``. A DataFrame is written with ``to_csv`` and
read by the same reader as the command (floats written in shortest round-trip form, so
the numbers are bit for bit the DataFrame's), and the result is the same ``balance.json``
the command writes (``to_dict()``), with its tables as DataFrames.
"""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Sequence

import pandas as pd

from . import _rotorid

Table = pd.DataFrame | str | os.PathLike[str]
Holes = int | tuple[int, float] | Sequence[float]


def _text(table: Table, what: str) -> tuple[str, str]:
    """(name for messages, CSV text) of a DataFrame or a path."""
    if isinstance(table, pd.DataFrame):
        return f"{what}_df", table.to_csv(index=False, lineterminator="\n")
    if isinstance(table, (str, os.PathLike)):
        path = os.fspath(table)
        with open(path, encoding="utf-8") as f:
            return path, f.read()
    raise TypeError(f"{what}: expected a pandas DataFrame or a CSV path, got {type(table).__name__}")


def _pairs(value: Mapping[str, float] | None, what: str) -> list[tuple[str, float]]:
    if value is None:
        return []
    if not isinstance(value, Mapping):
        raise TypeError(f"{what}: expected a dict of name -> number, got {type(value).__name__}")
    return [(str(k), float(v)) for k, v in value.items()]


def _holes(holes: Mapping[str, Holes] | None) -> tuple[list[tuple[str, tuple[int, float]]], list[tuple[str, list[float]]]]:
    equal: list[tuple[str, tuple[int, float]]] = []
    angles: list[tuple[str, list[float]]] = []
    for plane, h in (holes or {}).items():
        if isinstance(h, int) and not isinstance(h, bool):
            equal.append((str(plane), (h, 0.0)))
        elif isinstance(h, tuple) and len(h) == 2 and isinstance(h[0], int):
            equal.append((str(plane), (h[0], float(h[1]))))
        elif isinstance(h, Sequence) and not isinstance(h, str):
            angles.append((str(plane), [float(a) for a in h]))
        else:
            raise TypeError(
                f"holes[{plane!r}]: expected N (equally spaced, the first at 0 deg), (N, offset_deg) "
                f"or a list of hole angles in deg, got {h!r}"
            )
    return equal, angles


def _call(
    vectors: Table,
    masses: Table,
    current: str,
    *,
    plan: float | None,
    method: str,
    speeds: Sequence[float] | None,
    planes: Sequence[str] | None,
    limits: Mapping[str, float] | None,
    weights: Mapping[str, float] | None,
    radius: float | Mapping[str, float] | None,
    holes: Mapping[str, Holes] | None,
    mass_set: Sequence[float] | None,
    per_hole: int,
    phase: str | None,
    unit: str | None,
) -> dict[str, Any]:
    vname, vtext = _text(vectors, "vectors")
    mname, mtext = _text(masses, "masses")
    default_radius = None
    radii: list[tuple[str, float]] = []
    if isinstance(radius, Mapping):
        radii = _pairs(radius, "radius")
    elif radius is not None:
        default_radius = float(radius)
    equal, angles = _holes(holes)
    text = _rotorid.balance(
        vtext, mtext, str(current),
        vectors_name=vname, masses_name=mname, method=method,
        speeds=None if speeds is None else [float(s) for s in speeds],
        planes=None if planes is None else [str(p) for p in planes],
        limits=_pairs(limits, "limits"), weights=_pairs(weights, "weights"),
        radius=radii, default_radius=default_radius,
        holes_equal=equal, holes_angles=angles,
        mass_set=None if mass_set is None else [float(m) for m in mass_set],
        per_hole=int(per_hole), phase=phase, unit=unit, plan=plan,
    )
    return dict(json.loads(text))


class Balance:
    """A multi-plane balance; ``to_dict()`` equals ``balance.json`` of ``rotorid balance``."""

    def __init__(self, report: Mapping[str, Any]) -> None:
        self._d = dict(report)

    @property
    def method(self) -> str:
        """``least_squares`` or ``min_max``."""
        return str(self._d["method"])

    @property
    def corrections(self) -> pd.DataFrame:
        """Index plane; columns mass_kg, mass_kg_std, radius_m, angle_deg, angle_deg_std,
        unbalance_re_kg_m, unbalance_im_kg_m (angles from the keyphasor mark in the
        direction of rotation)."""
        rows = [{k: v for k, v in c.items() if k != "split"} for c in self._d["corrections"]]
        return pd.DataFrame(rows).set_index("plane")

    @property
    def split(self) -> pd.DataFrame:
        """One row per mass to place: plane, hole (1-based), angle_deg, mass_kg (empty
        without holes)."""
        rows = [
            {"plane": c["plane"], "hole": m["hole"], "angle_deg": m["angle_deg"], "mass_kg": m["mass_kg"]}
            for c in self._d["corrections"]
            if c["split"] is not None
            for m in c["split"]["masses"]
        ]
        return pd.DataFrame(rows, columns=["plane", "hole", "angle_deg", "mass_kg"])

    @property
    def residual(self) -> pd.DataFrame:
        """Index (sensor, speed_rpm): before and predicted 1X vectors with their std."""
        return pd.DataFrame(self._d["residual"]).set_index(["sensor", "speed_rpm"])

    @property
    def influence(self) -> pd.DataFrame:
        """Index (sensor, speed_rpm, plane): re, im [unit/(kg m)] with their std."""
        return pd.DataFrame(self._d["influence"]).set_index(["sensor", "speed_rpm", "plane"])

    @property
    def fit(self) -> pd.DataFrame:
        """Index (sensor, speed_rpm): runs, dof, residual_rms, as found, noise."""
        return pd.DataFrame(self._d["fit"]).set_index(["sensor", "speed_rpm"])

    @property
    def condition_number(self) -> float:
        return float(self._d["condition_number"])

    @property
    def warnings(self) -> list[str]:
        return list(self._d["warnings"])

    @property
    def notes(self) -> list[str]:
        return list(self._d["notes"])

    def to_dict(self) -> dict[str, Any]:
        return json.loads(json.dumps(self._d))

    def __repr__(self) -> str:
        c = self.corrections
        parts = [f"{p}: {r.mass_kg * 1e3:.4g} g at {r.angle_deg:.1f} deg" for p, r in c.iterrows()]
        return f"<rotorid.Balance {self.method} of run {self._d['current_run']!r}: {'; '.join(parts)}>"


class TrialPlan:
    """Planned trial masses; ``to_dict()`` equals ``balance.json`` of ``rotorid balance --plan``."""

    def __init__(self, report: Mapping[str, Any]) -> None:
        self._d = dict(report)

    @property
    def trials(self) -> pd.DataFrame:
        """Index plane; mass_kg, radius_m, angle_deg, the most sensitive sensor and speed,
        its current amplitude and the predicted change."""
        rows = [{k: v for k, v in t.items() if k != "split"} for t in self._d["trials"]]
        return pd.DataFrame(rows).set_index("plane")

    @property
    def notes(self) -> list[str]:
        return list(self._d["notes"])

    def to_dict(self) -> dict[str, Any]:
        return json.loads(json.dumps(self._d))


def balance(
    vectors: Table,
    masses: Table,
    current: str,
    *,
    method: str = "ls",
    speeds: Sequence[float] | None = None,
    planes: Sequence[str] | None = None,
    limits: Mapping[str, float] | None = None,
    weights: Mapping[str, float] | None = None,
    radius: float | Mapping[str, float] | None = None,
    holes: Mapping[str, Holes] | None = None,
    mass_set: Sequence[float] | None = None,
    per_hole: int = 1,
    phase: str | None = None,
    unit: str | None = None,
) -> Balance:
    """Balance run ``current`` by influence coefficients, as ``rotorid balance`` does.

    Args:
        vectors: 1X vectors (DataFrame or CSV path): run, speed_rpm, sensor, re, im
            (re + i im: the 1X component is Re((re + i im) e^{i phi}), phi from the
            keyphasor mark in the direction of rotation), or amp, phase_deg with ``phase``;
            unit, re_std/im_std or std optional.
        masses: calibration masses (DataFrame or CSV path): run, plane, mass_kg, radius_m,
            angle_deg (mass 0 for the run as found).
        current: the run to balance.
        method: ``"ls"`` (least squares) or ``"minmax"`` (smallest largest residual within
            ``limits``).
        speeds: only the vectors within 1 % of these speeds [rev/min].
        planes: the planes to correct (default all).
        limits: largest residual per sensor [its unit].
        weights: weight per sensor (default 1).
        radius: radius of the corrections [m], one for all planes or per plane (default:
            the calibration masses').
        holes: per plane, N (equally spaced from 0 deg), (N, offset_deg) or a list of
            angles [deg]: the correction is split into them.
        mass_set: available weights [kg] for the splits; ``per_hole`` stacked at most.
        phase: ``"lag"`` or ``"lead"``, the convention of amp, phase_deg.
        unit: the vectors' unit when the table has no unit column.

    Returns:
        :class:`Balance` (DataFrames ``corrections``, ``split``, ``residual``,
        ``influence``, ``fit``).

    Raises:
        ValueError: a bad table (naming its line, column, value and range) or option.
    """
    return Balance(_call(
        vectors, masses, current, plan=None, method=method, speeds=speeds, planes=planes,
        limits=limits, weights=weights, radius=radius, holes=holes, mass_set=mass_set,
        per_hole=per_hole, phase=phase, unit=unit,
    ))


def plan_trials(
    vectors: Table,
    masses: Table,
    current: str,
    fraction: float = 0.3,
    *,
    speeds: Sequence[float] | None = None,
    planes: Sequence[str] | None = None,
    radius: float | Mapping[str, float] | None = None,
    holes: Mapping[str, Holes] | None = None,
    mass_set: Sequence[float] | None = None,
    per_hole: int = 1,
    phase: str | None = None,
    unit: str | None = None,
) -> TrialPlan:
    """Trial masses changing the response by ``fraction`` at the most sensitive sensor,
    from the influence estimate of earlier calibration runs (``rotorid balance --plan``).
    Arguments as :func:`balance`."""
    return TrialPlan(_call(
        vectors, masses, current, plan=float(fraction), method="ls", speeds=speeds,
        planes=planes, limits=None, weights=None, radius=radius, holes=holes,
        mass_set=mass_set, per_hole=per_hole, phase=phase, unit=unit,
    ))
