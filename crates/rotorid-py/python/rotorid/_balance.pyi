import os
from typing import Any, Mapping, Sequence

import pandas as pd

Table = pd.DataFrame | str | os.PathLike[str]
Holes = int | tuple[int, float] | Sequence[float]

class Balance:
    """A multi-plane balance; ``to_dict()`` equals ``balance.json`` of ``rotorid balance``."""

    def __init__(self, report: Mapping[str, Any]) -> None: ...
    @property
    def method(self) -> str: ...
    @property
    def corrections(self) -> pd.DataFrame:
        """Index plane; mass_kg, mass_kg_std, radius_m, angle_deg, angle_deg_std, ..."""
    @property
    def split(self) -> pd.DataFrame:
        """plane, hole, angle_deg, mass_kg."""
    @property
    def residual(self) -> pd.DataFrame: ...
    @property
    def influence(self) -> pd.DataFrame: ...
    @property
    def fit(self) -> pd.DataFrame: ...
    @property
    def condition_number(self) -> float: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def notes(self) -> list[str]: ...
    def to_dict(self) -> dict[str, Any]: ...

class TrialPlan:
    """Planned trial masses; ``to_dict()`` equals ``balance.json`` of ``rotorid balance --plan``."""

    def __init__(self, report: Mapping[str, Any]) -> None: ...
    @property
    def trials(self) -> pd.DataFrame: ...
    @property
    def notes(self) -> list[str]: ...
    def to_dict(self) -> dict[str, Any]: ...

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
    """Balance run ``current`` by influence coefficients, as ``rotorid balance`` does."""

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
    """Trial masses changing the response by ``fraction`` at the most sensitive sensor."""
