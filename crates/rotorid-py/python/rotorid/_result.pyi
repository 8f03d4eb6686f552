from typing import Any, Mapping

import numpy as np
import pandas as pd

class Identification:
    """One identification; ``to_dict()`` equals the CLI's SUMMARY.json."""

    core_seconds: float | None
    def __init__(
        self,
        summary: str | Mapping[str, Any],
        estimates: Mapping[str, np.ndarray] | None = None,
        core_seconds: float | None = None,
    ) -> None: ...
    @property
    def method(self) -> str: ...
    @property
    def model(self) -> str:
        """``jeffcott`` or ``cross_coupled``."""
    @property
    def model_selection(self) -> pd.DataFrame | None:
        """Index model; columns estimated, log_likelihood, bic, adequate, noise_ratio_x,
        noise_ratio_z, converged, identifiable, chosen; None when the model was given."""
    @property
    def params(self) -> pd.DataFrame:
        """Index parameter (the model's names); columns value, std_error, crb, unit,
        truth, rel_error."""
    @property
    def warnings(self) -> list[str]: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def estimates(self) -> pd.DataFrame:
        """t [s], m_x, c_x, k_x, m_z, c_z, k_z, rcond_x, rcond_z, window."""
    @property
    def rotor(self) -> dict[str, float] | None: ...
    def to_dict(self) -> dict[str, Any]: ...
    def to_json(self, **kwargs: Any) -> str: ...
    def to_ross_bearing_kwargs(self) -> dict[str, float]:
        """ROSS's BearingElement coefficients [N/m, N s/m] (ROSS's y is rotorid's -z):
        Jeffcott {"kxx": kx, "kyy": kz, "cxx": cx, "cyy": cz}; cross-coupled also
        kxy = -kxz, kyx = -kzx, cxy = -cxz, cyx = -czx."""
    def _repr_html_(self) -> str: ...
    def plot(self, ax: Any = None) -> Any: ...
