import os
from typing import Any, Iterable

__all__ = ["BEARING_COEFFICIENTS", "export", "update"]

BEARING_COEFFICIENTS: tuple[str, ...]

def export(
    rotor: Any,
    matrices: str | os.PathLike[str],
    scenario: str | os.PathLike[str] | None = None,
    *,
    speed: float = 0.0,
    frequency: float | None = None,
    unbalance: Iterable[tuple[int, float, float]] = (),
) -> list[str]: ...
def update(rotor: Any, result: Any, *, speed: float = 0.0, frequency: float | None = None) -> Any: ...
