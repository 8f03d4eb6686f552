"""The result of an identification: the library's summary (``to_dict()``, the CLI's
SUMMARY.json) with tables and presentation on top. Nothing here computes an estimate."""

from __future__ import annotations

import copy
import html
import json
import math
from typing import Any, Mapping

import numpy as np
import pandas as pd

_PARAM_COLUMNS = ["value", "std_error", "crb", "unit", "truth", "rel_error"]
_SELECTION_COLUMNS = ["estimated", "log_likelihood", "bic", "adequate", "noise_ratio_x",
                      "noise_ratio_z", "converged", "identifiable", "chosen"]
# ROSS's BearingElement coefficients from rotorid's, per model: (ROSS name, rotorid name,
# sign). ROSS's x is rotorid's x and ROSS's y is rotorid's -z (to_ross_bearing_kwargs).
_ROSS = {
    "jeffcott": [("kxx", "kx", 1.0), ("kyy", "kz", 1.0), ("cxx", "cx", 1.0), ("cyy", "cz", 1.0)],
    "cross_coupled": [
        ("kxx", "kxx", 1.0), ("kyy", "kzz", 1.0), ("kxy", "kxz", -1.0), ("kyx", "kzx", -1.0),
        ("cxx", "cxx", 1.0), ("cyy", "czz", 1.0), ("cxy", "cxz", -1.0), ("cyx", "czx", -1.0),
    ],
}


def _nan(v: Any) -> float:
    return math.nan if v is None else float(v)


def _severity(d: Mapping[str, Any]) -> str:
    # schema 2 had no severity: every diagnostic was a warning
    return d.get("severity", "warning")


def _fmt(v: Any) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    return html.escape(str(v))


class Identification:
    """One identification (``rotorid.identify`` or ``Session.finish``).

    Attributes:
        model: the rotor model the values belong to, ``"jeffcott"`` or ``"cross_coupled"``.
        params: DataFrame indexed by the model's parameter names (Jeffcott: m, cx, kx, cz,
            kz; cross-coupled: m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz; then a, mud,
            alpha when estimated; m_x and m_z for the per-direction methods) with columns
            value, std_error, crb [the parameter's unit], unit, truth and rel_error
            ((value - truth) / truth); NaN where not determined or not given.
        warnings: the messages of the diagnostics of severity warning, worst first (what
            the CLI prints as ``warning:``): the numbers they concern must not be relied on
            as they stand.
        notes: the messages of the diagnostics of severity note (the CLI's ``note:``):
            worth knowing, the numbers stand (which model ``model="auto"`` took and why;
            that cross-coupled bearings explain data a Jeffcott fit could not; time stamps
            accepted as rounded).
        model_selection: how ``model="auto"`` chose the model (a DataFrame, one row per
            candidate), or None when the model was given.
        estimates: DataFrame t [s], m_x, c_x, k_x, m_z, c_z, k_z [kg, N s/m, N/m],
            rcond_x, rcond_z, window: algebraic: one row per sample, values NaN where a
            direction is ill-conditioned (the CLI leaves them empty), window the restart
            window of the estimate (``restart``; 0.0, 1.0, ... as they start, 0.0 throughout
            without restarts); modulating and refine: the one row the CLI writes (window
            NaN).
        core_seconds: time spent in the library (identify only; for benchmarks).
    """

    def __init__(
        self,
        summary: str | Mapping[str, Any],
        estimates: Mapping[str, np.ndarray] | None = None,
        core_seconds: float | None = None,
    ) -> None:
        self._summary = json.loads(summary) if isinstance(summary, str) else dict(summary)
        self._estimate_columns = dict(estimates) if estimates is not None else None
        self._params: pd.DataFrame | None = None
        self._estimates: pd.DataFrame | None = None
        self.core_seconds = core_seconds

    @property
    def method(self) -> str:
        """``algebraic``, ``modulating`` or ``refine``."""
        return self._summary["method"]

    @property
    def model(self) -> str:
        """``jeffcott`` or ``cross_coupled``: whose parameters the values are (a schema 2
        summary, which had no such field, is ``jeffcott``)."""
        return self._summary.get("model", "jeffcott")

    @property
    def model_selection(self) -> pd.DataFrame | None:
        """How ``model="auto"`` chose the model; None when the model was given.

        One row per candidate model, simplest first, indexed by model: estimated (the
        quantities estimated: parameters, initial state and the two noise levels),
        log_likelihood (the maximised Gaussian log-likelihood of x and z), bic
        (-2 log_likelihood + estimated ln(2N); lower is better), adequate (the residuals
        pass the adequacy test; None when not tested), noise_ratio_x, noise_ratio_z
        (residual over the data's noise level), converged, identifiable, chosen (the
        model taken). ``attrs["criterion"]`` and ``attrs["reason"]`` give the rule and
        why, in words (docs/summary.md, ``model_selection``).
        """
        sel = self._summary.get("model_selection")
        if sel is None:
            return None
        rows = sel["candidates"]

        def ratio(c: Mapping[str, Any], d: str) -> float:
            r = c.get("noise_ratio")
            return _nan(None if r is None else r.get(d))

        df = pd.DataFrame(
            {
                "estimated": [c["estimated"] for c in rows],
                "log_likelihood": [_nan(c["log_likelihood"]) for c in rows],
                "bic": [_nan(c["bic"]) for c in rows],
                "adequate": pd.array([c["adequate"] for c in rows], dtype="boolean"),
                "noise_ratio_x": [ratio(c, "x") for c in rows],
                "noise_ratio_z": [ratio(c, "z") for c in rows],
                "converged": [bool(c["converged"]) for c in rows],
                "identifiable": [bool(c["identifiable"]) for c in rows],
                "chosen": [c["model"] == sel["chosen"] for c in rows],
            },
            index=pd.Index([c["model"] for c in rows], name="model"),
            columns=_SELECTION_COLUMNS,
        )
        df.attrs["criterion"] = sel["criterion"]
        df.attrs["reason"] = sel["reason"]
        return df

    @property
    def params(self) -> pd.DataFrame:
        if self._params is None:
            rows = self._summary["parameters"]
            self._params = pd.DataFrame(
                {
                    "value": [_nan(r["value"]) for r in rows],
                    "std_error": [_nan(r["std_error"]) for r in rows],
                    "crb": [_nan(r["crb"]) for r in rows],
                    "unit": [r["unit"] for r in rows],
                    "truth": [_nan(r["truth"]) for r in rows],
                    "rel_error": [_nan(r["relative_error"]) for r in rows],
                },
                index=pd.Index([r["parameter"] for r in rows], name="parameter"),
                columns=_PARAM_COLUMNS,
            )
        return self._params

    @property
    def warnings(self) -> list[str]:
        return [d["message"] for d in self._summary["diagnostics"] if _severity(d) == "warning"]

    @property
    def notes(self) -> list[str]:
        return [d["message"] for d in self._summary["diagnostics"] if _severity(d) == "note"]

    @property
    def estimates(self) -> pd.DataFrame:
        if self._estimates is None:
            cols = self._estimate_columns or {}
            from . import ESTIMATE_COLUMNS_BY_MODEL

            names = ESTIMATE_COLUMNS_BY_MODEL[self._summary.get("model", "jeffcott")]
            self._estimates = pd.DataFrame(
                {k: cols.get(k, np.empty(0)) for k in names}, copy=False
            )
        return self._estimates

    @property
    def rotor(self) -> dict[str, float] | None:
        """Every parameter of the model (estimated, else known) when all the estimated ones
        are determined, keyed by the model's names in its order: Jeffcott m [kg], cx
        [N s/m], kx [N/m], cz, kz; cross-coupled m, cxx, cxz, czx, czz [N s/m], kxx, kxz,
        kzx, kzz [N/m]; then a [N s^2/m], mud [kg m], alpha [rad]. None otherwise (see
        :attr:`warnings`). Check :attr:`model` before reading it as one model's rotor."""
        r = self._summary.get("rotor")
        return dict(r) if r is not None else None

    def to_dict(self) -> dict[str, Any]:
        """The summary: equal to ``json.load`` of the CLI's SUMMARY.json for the same
        record and options (with ``input`` and ``scenario`` as given to ``identify``)."""
        return copy.deepcopy(self._summary)

    def to_json(self, **kwargs: Any) -> str:
        """The summary as JSON text (``json.dumps`` keyword arguments pass through)."""
        return json.dumps(self._summary, **kwargs)

    def to_ross_bearing_kwargs(self) -> dict[str, float]:
        """The bearing coefficients as ROSS's ``BearingElement`` takes them: stiffness
        [N/m] and damping [N s/m] of the whole support, in ROSS's frame.

        Frames: rotorid's x (horizontal) is ROSS's x and rotorid's z (vertical) is ROSS's
        -y. rotorid's shaft turns from +z towards +x, ROSS's from +x towards +y; the map
        (x, z) -> (x, -z) is the rotation that takes one sense of rotation to the other,
        so forward whirl stays forward whirl. A displacement transforms as q_ROSS = D q
        with D = diag(1, -1), a force likewise, hence K_ROSS = D K D and C_ROSS = D C D:

        - cross-coupled model: ``kxx = kxx, kyy = kzz, kxy = -kxz, kyx = -kzx`` and
          ``cxx = cxx, cyy = czz, cxy = -cxz, cyx = -czx`` (ROSS's kxy, like rotorid's
          kxz, is the restoring force in x per unit displacement in y);
        - Jeffcott model: ``{"kxx": kx, "kyy": kz, "cxx": cx, "cyy": cz}``.

        The unbalance angle maps as alpha_ROSS = alpha - 90 deg (rotorid measures it from
        +z, ROSS from +x). The values are the whole support's: a rotor on two bearings
        takes the share of each (half each when symmetric). See docs/ross.md.

        Raises:
            ValueError: when one of them was not determined.
        """
        rotor = self._summary.get("rotor")
        values = {}
        missing = []
        for ross, ours, sign in _ROSS[self.model]:
            if rotor is not None:
                values[ross] = sign * float(rotor[ours])
                continue
            v = self.params["value"].get(ours, math.nan)
            if math.isnan(v):
                missing.append(ours)
            else:
                values[ross] = sign * float(v)
        if missing:
            raise ValueError(
                f"{', '.join(missing)} not determined by this identification: see its warnings"
            )
        return values

    def __repr__(self) -> str:
        p = self.params
        lines = [f"<rotorid.Identification method={self.method} "
                 f"samples={self._summary['record']['samples']} model={self.model}>"]
        for name, r in p.iterrows():
            std = "" if math.isnan(r["std_error"]) else f" +- {r['std_error']:.3g}"
            lines.append(f"  {name:6s} {r['value']:.6g}{std} {r['unit']}")
        lines += [f"  warning: {w}" for w in self.warnings]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rec = self._summary["record"]
        how = "chosen by model=\"auto\"" if self.model_selection is not None else "given"
        head = (
            f"<p><b>rotorid {html.escape(self.method)}</b>, model "
            f"<b>{html.escape(self.model)}</b> ({how}): {rec['samples']} samples, "
            f"t = {rec['t_first_s']:.6g} .. {rec['t_last_s']:.6g} s, dt = {rec['dt_s']:.6g} s</p>"
        )
        cols = ["parameter", *_PARAM_COLUMNS]
        rows = "".join(
            "<tr>" + "".join(f"<td>{_fmt(v)}</td>" for v in (name, *r.tolist())) + "</tr>"
            for name, r in self.params.iterrows()
        )
        table = (
            "<table><thead><tr>"
            + "".join(f"<th>{c}</th>" for c in cols)
            + f"</tr></thead><tbody>{rows}</tbody></table>"
        )
        sel = self.model_selection
        selection = ""
        if sel is not None:
            scols = ["model", *_SELECTION_COLUMNS]
            srows = "".join(
                "<tr>" + "".join(f"<td>{_fmt(None if pd.isna(v) else v)}</td>"
                                 for v in (name, *r.tolist())) + "</tr>"
                for name, r in sel.iterrows()
            )
            selection = (
                "<p>Model selection:</p><table><thead><tr>"
                + "".join(f"<th>{c}</th>" for c in scols)
                + f"</tr></thead><tbody>{srows}</tbody></table>"
            )
        warns = "".join(f"<li>{html.escape(w)}</li>" for w in self.warnings)
        notes = "".join(f"<li>{html.escape(n)}</li>" for n in self.notes)
        return (head + table + selection
                + (f"<p>Warnings:</p><ul>{warns}</ul>" if warns else "")
                + (f"<p>Notes:</p><ul>{notes}</ul>" if notes else ""))

    def plot(self, ax: Any = None) -> Any:
        """Draw the estimates with matplotlib (``pip install rotorid[plot]``).

        algebraic: m [kg], c [N s/m], k [N/m] of each direction against t [s], with the
        truth dashed. modulating and refine: each parameter's value relative to the truth
        (or to itself when no truth is given), with its standard error and, where
        computed, the Cramer-Rao bound. Returns the Figure.
        """
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("plot() needs matplotlib: pip install 'rotorid[plot]'") from e
        if self.method == "algebraic":
            return self._plot_algebraic(plt)
        return self._plot_batch(plt, ax)

    def _plot_algebraic(self, plt: Any) -> Any:
        e = self.estimates
        truth = self.params["truth"]
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
        # the value columns between t and rcond_x: m_x, c_x, ... or m_x, cxx, cxz, ...
        values = [c for c in e.columns if c not in ("t", "rcond_x", "rcond_z", "window")]
        for ax, q, unit in zip(axes, "mck", ("kg", "N s/m", "N/m")):
            for column in (c for c in values if c.startswith(q)):
                # the parameter's name: m_x stays, c_x is cx, cxz is cxz
                name = column if q == "m" else column.replace("_", "")
                ax.plot(e["t"], e[column], label=column, lw=1)
                if name in truth.index and not math.isnan(truth[name]):
                    ax.axhline(truth[name], ls="--", lw=0.8, color="k")
            ax.set_ylabel(f"{q} [{unit}]")
            ax.legend(loc="best")
        axes[-1].set_xlabel("t [s]")
        fig.tight_layout()
        return fig

    def _plot_batch(self, plt: Any, ax: Any) -> Any:
        p = self.params
        ref = p["truth"].where(~p["truth"].isna(), p["value"])
        rel = p["value"] / ref - 1.0
        err = p["std_error"] / ref.abs()
        if ax is None:
            fig, ax = plt.subplots(figsize=(7, 3.5))
        else:
            fig = ax.figure
        x = np.arange(len(p))
        ax.errorbar(x, rel, yerr=err, fmt="o", capsize=4, label="estimate +- std error")
        crb = p["crb"] / ref.abs()
        if not crb.isna().all():
            ax.errorbar(x + 0.15, np.zeros(len(p)), yerr=crb, fmt="none", ecolor="gray",
                        capsize=4, label="Cramer-Rao bound")
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xticks(x, list(p.index))
        basis = "truth" if not p["truth"].isna().all() else "value"
        ax.set_ylabel(f"relative to {basis}")
        ax.set_title(f"rotorid {self.method}")
        ax.legend(loc="best")
        fig.tight_layout()
        return fig
