"""Run-ups and coast-downs from Python: ``rotorid.transient`` (docs/transient.md).

The same analysis as ``rotorid transient``, through the same code: raw records (probes in
volts and a keyphasor, in any format rotorid reads) described by a scenario's
``[acquisition]``, or a 1X table (a CSV path, a DataFrame or a dict of columns, read by
the command's reader, with its messages). The result's ``to_dict()`` is the command's
``transient.json`` (``figures`` empty: no figures are drawn here) and its ``bode`` the rows
of ``bode.csv``, the numbers bit for bit the command's.
"""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Sequence

import numpy as np
import pandas as pd

from . import _rotorid

BODE_COLUMNS = ["speed_rpm", "sensor", "order", "amplitude", "phase_lag_deg", "re", "im", "std", "raw_re", "raw_im"]
CRITICAL_COLUMNS = [
    "sensor", "order", "rpm", "rpm_std", "amplitude", "amplitude_std", "unit", "phase_lag_deg",
    "n1_rpm", "n1_rpm_std", "n2_rpm", "n2_rpm_std", "amplification_factor",
    "amplification_factor_std", "damping_ratio", "damping_ratio_std", "significance",
    "sweep_rpm_per_s", "position", "separation_margin_pct", "required_margin_pct", "margin_ok",
]
_FLOAT_CRITICAL = {
    "rpm", "rpm_std", "amplitude", "amplitude_std", "phase_lag_deg", "n1_rpm", "n1_rpm_std",
    "n2_rpm", "n2_rpm_std", "amplification_factor", "amplification_factor_std", "damping_ratio",
    "damping_ratio_std", "significance", "sweep_rpm_per_s", "separation_margin_pct",
    "required_margin_pct",
}

Records = str | os.PathLike[str] | Sequence[str | os.PathLike[str]]
VectorTable = pd.DataFrame | Mapping[str, Any] | str | os.PathLike[str]


def _vectors_text(table: VectorTable) -> tuple[str, str]:
    """(name for messages, CSV text) of a DataFrame, a dict of columns or a path. A
    DataFrame's floats are written in shortest round-trip form, so the reader gets its
    numbers bit for bit; its row k is line k + 2 in messages."""
    if isinstance(table, Mapping):
        table = pd.DataFrame(dict(table))
    if isinstance(table, pd.DataFrame):
        return "vectors_df", table.to_csv(index=False, lineterminator="\n")
    if isinstance(table, (str, os.PathLike)):
        path = os.fspath(table)
        with open(path, encoding="utf-8") as f:
            return path, f.read()
    raise TypeError(
        f"vectors: expected a pandas DataFrame, a dict of columns or a CSV path, got {type(table).__name__}"
    )


def _slow_roll(value: Any) -> tuple[str, Any]:
    """(kind, value) of ``slow_roll=``: None (the scenario's record, else auto), "auto",
    "none", (min_rpm, max_rpm), "MIN:MAX" as on the command line, or a record's path."""
    if value is None:
        return "default", None
    if isinstance(value, tuple) and len(value) == 2:
        return "range", (float(value[0]), float(value[1]))
    if isinstance(value, os.PathLike):
        return "file", os.fspath(value)
    if isinstance(value, str):
        if value in ("auto", "none"):
            return value, None
        if ":" in value and not os.path.exists(value):
            lo, _, hi = value.partition(":")
            try:
                return "range", (float(lo), float(hi))
            except ValueError:
                raise ValueError(
                    f"slow_roll={value!r}: give MIN:MAX in rev/min (e.g. \"300:500\"), a (min, max) "
                    "tuple, \"auto\", \"none\" or a slow-roll record's path"
                ) from None
        return "file", value
    raise TypeError(
        f"slow_roll: expected \"auto\", \"none\", (min_rpm, max_rpm) or a path, got {type(value).__name__}"
    )


#: The columns of :attr:`Transient.modes`: ``transient.json``'s ``modes[]`` fields.
MODE_COLUMNS = [
    "rpm",
    "rpm_std",
    "damping_ratio",
    "damping_ratio_std",
    "log_decrement",
    "log_decrement_std",
]


class Transient:
    """A run-up or coast-down analysed (``rotorid.transient``); ``to_dict()`` equals the
    ``transient.json`` of ``rotorid transient`` on the same input (``figures`` empty).

    Attributes:
        bode: DataFrame with the columns of ``bode.csv``: speed_rpm [rev/min], sensor,
            order, amplitude [m, zero-to-peak], phase_lag_deg [deg, 0..360), re, im [m]
            (slow-roll compensated), std [m] (of each of re and im; NaN when unknown),
            raw_re, raw_im [m] (as measured); one row per revolution (or bin, or table
            row), sensor and order, in time order.
        criticals: DataFrame, one row per critical speed (by sensor, then speed), with the
            fields of ``transient.json``'s ``criticals[]`` (``CRITICAL_COLUMNS``; NaN where
            the record does not determine one, the margin columns NaN / None without
            ``operating_rpm``).
        notes: what the analysis says about the input (the automatic slow-roll range,
            one probe only, a table taken as compensated), as the command prints them.
        direction: ``run_up``, ``coast_down`` or ``mixed``.
    """

    def __init__(self, text: str, bode: Mapping[str, Any] | None = None) -> None:
        self._json = text
        self._d = json.loads(text)
        self._bode_columns = dict(bode) if bode is not None else None
        self._bode: pd.DataFrame | None = None

    @property
    def json(self) -> str:
        """``transient.json``'s text as the command writes it (without the final newline)."""
        return self._json

    def to_dict(self) -> dict[str, Any]:
        """``transient.json`` as a dict (a fresh copy)."""
        return json.loads(self._json)

    def to_json(self, **kwargs: Any) -> str:
        """``transient.json`` as JSON text (``json.dumps`` keyword arguments pass through)."""
        return json.dumps(self._d, **kwargs)

    @property
    def direction(self) -> str:
        return str(self._d["direction"])

    @property
    def notes(self) -> list[str]:
        return list(self._d["notes"])

    @property
    def sensors(self) -> list[str]:
        """The sensors' names (the probes' columns, or the table's sensors)."""
        return [s["name"] for s in self._d["sensors"]]

    @property
    def bode(self) -> pd.DataFrame:
        if self._bode is None:
            if self._bode_columns is None:
                raise ValueError("bode: this result was made from transient.json alone, which holds no Bode rows")
            c = self._bode_columns
            self._bode = pd.DataFrame({k: c[k] for k in BODE_COLUMNS}, columns=BODE_COLUMNS)
            self._bode["order"] = self._bode["order"].astype("int64")
        return self._bode.copy()

    @property
    def criticals(self) -> pd.DataFrame:
        rows = self._d["criticals"]
        data: dict[str, Any] = {}
        for k in CRITICAL_COLUMNS:
            vals = [r.get(k) for r in rows]
            if k in _FLOAT_CRITICAL:
                data[k] = np.array([np.nan if v is None else float(v) for v in vals], dtype=float)
            elif k == "margin_ok":
                data[k] = pd.array(vals, dtype="boolean")
            elif k == "order":
                data[k] = np.array(vals, dtype="int64")
            else:
                data[k] = vals
        return pd.DataFrame(data, columns=CRITICAL_COLUMNS)

    @property
    def modes(self) -> pd.DataFrame:
        rows = self._d.get("modes") or []
        return pd.DataFrame(
            {k: np.array([np.nan if r.get(k) is None else float(r[k]) for r in rows], dtype=float) for k in MODE_COLUMNS},
            columns=MODE_COLUMNS,
        )

    @property
    def mode_fit(self) -> dict[str, Any] | None:
        return self._d.get("mode_fit")

    def __repr__(self) -> str:
        lo, hi = self._d["speed_rpm"]
        crit = "; ".join(
            f"{c['sensor']} {c['rpm']:.0f} rpm"
            + (f" AF {c['amplification_factor']:.1f}" if c.get("amplification_factor") is not None else "")
            for c in self._d["criticals"]
        )
        return (
            f"<rotorid.Transient {self.direction.replace('_', '-')} {lo:.0f}..{hi:.0f} rpm, "
            f"criticals: {crit or 'none'}>"
        )


def transient(
    records: Records | None = None,
    *,
    scenario: Any = None,
    vectors: VectorTable | None = None,
    slow_roll: Any = None,
    orders: Sequence[int] | None = None,
    operating_rpm: tuple[float, float] | None = None,
    bin_rpm: float | None = None,
    amplitude: str = "pk",
    unit: str | None = None,
) -> Transient:
    """Analyse a run-up or coast-down as ``rotorid transient`` does (docs/transient.md).

    Args:
        records: the records of one event in time order (a path or a list of paths; any
            format rotorid reads): raw records (probe volts and a keyphasor) with the
            columns the scenario's ``[acquisition]`` names, or, with a scenario without
            ``[acquisition]`` or none, recordings as ``rotorid publish`` sends them (t, x, z
            [s, m] and phi [rad]: the revolutions are where phi passes 2 pi k; x and z are
            probes at 0 and 90 deg).
        scenario: a ``rotorid.Scenario`` or the path of a scenario TOML: its
            ``[acquisition]`` describes raw records (nothing else is needed); for a
            recording without phi, its ``[speed]`` profile gives phi.
        vectors: a 1X table instead of records (no scenario): a DataFrame, a dict of
            columns or a CSV path with ``speed_rpm, sensor`` and ``amplitude,
            phase_lag_deg`` or ``re, im``; optional ``unit`` (m, mm, um, mil), ``std`` or
            ``re_std, im_std``.
        slow_roll: the runout subtracted: None (the scenario's ``[acquisition.runout]``
            slow-roll record when it names one, else ``"auto"``), ``"auto"`` (the record's
            lowest speeds), ``"none"``, ``(min_rpm, max_rpm)`` or ``"MIN:MAX"``, or the path
            of a slow-roll record.
        orders: the orders to track (default 1 and 2).
        operating_rpm: the operating range (min, max) [rev/min], for API 684 separation
            margins.
        bin_rpm: average the revolutions in speed bins of this width [rev/min].
        amplitude: a table's amplitudes, ``"pk"`` (zero-to-peak) or ``"pk-pk"``.
        unit: a table's unit when it has no unit column or header suffix.

    Raises:
        ValueError: an input the analysis cannot use; the message names the file, the line
            or channel, the value and what is allowed, as the command's.
        OSError: a file that cannot be read.
    """
    kind, value = _slow_roll(slow_roll)
    if isinstance(records, (str, os.PathLike)):
        paths = [os.fspath(records)]
    elif records is None:
        paths = []
    else:
        paths = [os.fspath(r) for r in records]
    scenario_arg: Any = None
    if scenario is not None:
        scenario_arg = scenario if isinstance(scenario, _rotorid.Scenario) else os.fspath(scenario)
    vname, vtext = _vectors_text(vectors) if vectors is not None else (None, None)
    op = None
    if operating_rpm is not None:
        lo, hi = operating_rpm
        op = (float(lo), float(hi))
    text, bode, read_notes = _rotorid.transient(
        paths,
        scenario=scenario_arg,
        vectors=vtext,
        vectors_name=vname,
        amplitude=amplitude,
        unit=unit,
        slow_roll_kind=kind,
        slow_roll_file=value if kind == "file" else None,
        slow_roll_range=value if kind == "range" else None,
        orders=None if orders is None else [int(o) for o in orders],
        operating_rpm=op,
        bin_rpm=None if bin_rpm is None else float(bin_rpm),
    )
    if read_notes:
        import warnings

        for file, note in read_notes:
            warnings.warn(f"{file}: {note}", UserWarning, stacklevel=2)
    return Transient(text, bode)
