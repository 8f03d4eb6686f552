import os
from typing import Any, Mapping, Sequence

import pandas as pd

BODE_COLUMNS: list[str]
CRITICAL_COLUMNS: list[str]

Records = str | os.PathLike[str] | Sequence[str | os.PathLike[str]]
VectorTable = pd.DataFrame | Mapping[str, Any] | str | os.PathLike[str]

MODE_COLUMNS: list[str]

class Transient:
    """A run-up or coast-down analysed; ``to_dict()`` equals ``transient.json`` of
    ``rotorid transient`` on the same input (``figures`` empty)."""

    def __init__(self, text: str, bode: Mapping[str, Any] | None = None) -> None: ...
    @property
    def json(self) -> str:
        """``transient.json``'s text as the command writes it (without the final newline)."""
    def to_dict(self) -> dict[str, Any]: ...
    def to_json(self, **kwargs: Any) -> str: ...
    @property
    def direction(self) -> str:
        """``run_up``, ``coast_down`` or ``mixed``."""
    @property
    def notes(self) -> list[str]: ...
    @property
    def sensors(self) -> list[str]: ...
    @property
    def bode(self) -> pd.DataFrame:
        """The columns of ``bode.csv``: speed_rpm, sensor, order, amplitude, phase_lag_deg,
        re, im, std, raw_re, raw_im (SI, zero-to-peak; std NaN when unknown)."""
    @property
    def criticals(self) -> pd.DataFrame:
        """One row per critical with the fields of ``transient.json``'s ``criticals[]``."""
    @property
    def modes(self) -> pd.DataFrame:
        """One row per fitted mode (``MODE_COLUMNS``: natural speed rpm, damping ratio, log
        decrement, each with its std), from ``transient.json``'s ``modes[]``."""
    @property
    def mode_fit(self) -> dict[str, Any] | None:
        """How the modes were fitted (basis, sensors, window, adequacy, BIC candidates)."""

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
    """Analyse a run-up or coast-down as ``rotorid transient`` does (docs/transient.md)."""
