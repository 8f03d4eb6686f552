"""The bridge to ROSS, the rotordynamics library (``ross-rotordynamics``): a ``ross.Rotor``
out as rotorid's finite-element rotor (its matrices file and scenario, ``docs/formats.md``),
and the identified bearing coefficients back in as a ``ross.Rotor``.

Conventions (checked against ROSS 3.1.0 by ``tests_ross/test_ross_export.py``): ROSS builds
6 degrees of freedom per node, ``x, y, z, alpha, beta, theta``; the lateral ones, node-major
``x, y, alpha, beta`` (what ``ross.utils.convert_6dof_to_4dof`` keeps), are rotorid's
``<node>.x, <node>.y, <node>.rx, <node>.ry``: ROSS's alpha is the right-hand rotation about
+x with dy/dz = -alpha, its beta the rotation about +y with dx/dz = +beta (a rigid tilt with
those slopes is in the null space of ROSS's shaft stiffness; with the opposite signs it is
not), nodes numbered along +z, the shaft turning from +x towards +y. ROSS's equation of
motion ``M q'' + (C + w G) q' + (K + w' Ksdt) q = F`` is rotorid's with ``Ka = Ksdt``;
its bearings' restoring force is ``-K_b q - C_b q'`` as rotorid's, and its unbalance
(magnitude, phase) is rotorid's (m_u d, alpha).

ROSS is imported when a function is called, so ``import rotorid.ross`` works without it.
"""

from __future__ import annotations

import math
import os
from typing import Any, Iterable, Mapping

import numpy as np

__all__ = ["BEARING_COEFFICIENTS", "export", "update"]

#: The eight coefficients of a bearing, as the scenario and the parameters name them
#: (stiffness in N/m, damping in N s/m), in ROSS's ``BearingElement`` keywords too.
BEARING_COEFFICIENTS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")

_DOF_NAMES = ("x", "y", "rx", "ry")
# Positions of x, y, alpha, beta among a node's degrees of freedom in ROSS
_LATERAL = {6: (0, 1, 3, 4), 4: (0, 1, 2, 3)}


def _lateral(rotor: Any) -> tuple[np.ndarray, list[str]]:
    """The indices of the lateral degrees of freedom of ``rotor`` among ROSS's, node-major
    ``x, y, alpha, beta``, and their names ``<node>.<dof>``."""
    per_node = int(rotor.number_dof)
    if per_node not in _LATERAL:
        raise ValueError(f"rotor.number_dof = {per_node}: rotorid.ross reads ROSS rotors of 4 or 6 degrees of freedom per node")
    n_nodes = int(rotor.ndof) // per_node
    if n_nodes * per_node != int(rotor.ndof):
        raise ValueError(f"rotor.ndof = {rotor.ndof} is not a multiple of number_dof = {per_node}")
    index = [per_node * node + k for node in range(n_nodes) for k in _LATERAL[per_node]]
    names = [f"{node}.{d}" for node in range(n_nodes) for d in _DOF_NAMES]
    return np.asarray(index), names


def _bearings(rotor: Any, speed: float, frequency: float | None) -> list[dict[str, float]]:
    """Each bearing of ``rotor`` (in ``rotor.bearing_elements``' order: bearing0, ...) as
    its node and eight coefficients at ``speed`` [rad/s] and whirl ``frequency`` [rad/s]
    (default: synchronous, the speed)."""
    f = speed if frequency is None else frequency
    out = []
    for i, b in enumerate(rotor.bearing_elements):
        what = f"bearing{i} ({type(b).__name__} at node {b.n}, tag {b.tag!r})"
        if getattr(b, "n_link", None) is not None:
            raise ValueError(f"{what} links node {b.n} to node {b.n_link}: rotorid's bearings connect a node to the ground only")
        k = np.asarray(b.K(f, speed=speed), dtype=float)
        c = np.asarray(b.C(f, speed=speed), dtype=float)
        m = np.asarray(b.M(f, speed=speed), dtype=float)
        if np.any(m[:2, :2] != 0):
            raise ValueError(f"{what} has mass coefficients {m[:2, :2].tolist()} kg: rotorid's bearings have stiffness and damping only")
        out.append({
            "node": int(b.n),
            "kxx": float(k[0, 0]), "kxy": float(k[0, 1]), "kyx": float(k[1, 0]), "kyy": float(k[1, 1]),
            "cxx": float(c[0, 0]), "cxy": float(c[0, 1]), "cyx": float(c[1, 0]), "cyy": float(c[1, 1]),
        })
    return out


def _toml_number(v: float) -> str:
    if not math.isfinite(v):
        raise ValueError(f"a coefficient or unbalance of {v}: every value must be finite")
    return repr(float(v))


def export(
    rotor: Any,
    matrices: str | os.PathLike[str],
    scenario: str | os.PathLike[str] | None = None,
    *,
    speed: float = 0.0,
    frequency: float | None = None,
    unbalance: Iterable[tuple[int, float, float]] = (),
) -> list[str]:
    """Write the finite-element model of the ``ross.Rotor`` ``rotor`` for rotorid.

    ``matrices`` gets the NPZ of its shaft and disks without the bearings (ROSS's
    ``M0``, ``K0``, ``G0``, ``Ksdt0`` as ``Ka``, and ``C0`` as ``C`` when ROSS has shaft
    damping, i.e. it is not all zero), restricted to the lateral degrees of freedom
    (module doc), with ``dofs``. ``scenario``, if given, gets a scenario TOML with
    ``[rotor] model = "finite_element"``, ``matrices`` (the path of the NPZ relative to the
    scenario's directory), one ``[[rotor.bearing]]`` per bearing of ``rotor`` (in the order
    of ``rotor.bearing_elements``, by node: bearing0, bearing1, ...) with its coefficients
    evaluated at ``speed`` [rad/s] and whirl ``frequency`` [rad/s] (default: the speed;
    ROSS's bearing coefficients may depend on both, rotorid's are constant), and one
    ``[[rotor.unbalance]]`` per ``(node, magnitude, phase)`` of ``unbalance`` (as ROSS's
    ``run_unbalance_response`` takes them: magnitude m_u d in kg m, phase in rad), written
    ``m_u = magnitude``, ``d = 1.0``. The scenario has no ``[speed]`` or ``[sampling]``:
    add them for a simulation. Refused (``ValueError``): a bearing linked to another node
    (``n_link``), a bearing with mass coefficients, a non-finite value.

    Returns the names of the degrees of freedom, in the matrices' order.
    """
    index, dofs = _lateral(rotor)
    pick = np.ix_(index, index)
    arrays: dict[str, Any] = {
        "dofs": np.array(dofs, dtype=str),
        "M": np.ascontiguousarray(rotor.M0[pick], dtype=np.float64),
        "K": np.ascontiguousarray(rotor.K0[pick], dtype=np.float64),
        "G": np.ascontiguousarray(rotor.G0[pick], dtype=np.float64),
        "Ka": np.ascontiguousarray(rotor.Ksdt0[pick], dtype=np.float64),
    }
    c0 = np.asarray(rotor.C0, dtype=np.float64)[pick]
    if np.any(c0 != 0):
        arrays["C"] = np.ascontiguousarray(c0)
    bearings = _bearings(rotor, float(speed), frequency)
    unbalances = [(int(n), float(mag), float(ph)) for n, mag, ph in unbalance]
    for n, mag, _ in unbalances:
        if not 0 <= n < len(dofs) // 4:
            raise ValueError(f"unbalance at node {n}: the rotor has nodes 0 .. {len(dofs) // 4 - 1}")
        if not (math.isfinite(mag) and mag >= 0):
            raise ValueError(f"unbalance at node {n}: magnitude {mag} kg m must be finite and >= 0")
    matrices = os.fspath(matrices)
    with open(matrices, "wb") as f:
        np.savez(f, **arrays)
    if scenario is None:
        return dofs
    scenario = os.fspath(scenario)
    rel = os.path.relpath(os.path.abspath(matrices), os.path.dirname(os.path.abspath(scenario)))
    lines = [
        "# A finite-element rotor exported from ROSS by rotorid.ross.export (docs/formats.md).",
        f"# Bearing coefficients at speed = {float(speed)!r} rad/s, whirl frequency = "
        f"{float(speed if frequency is None else frequency)!r} rad/s.",
        "[rotor]",
        'model = "finite_element"',
        f"matrices = {_toml_string(rel.replace(os.sep, '/'))}",
    ]
    for i, b in enumerate(bearings):
        lines += ["", f"[[rotor.bearing]]  # bearing{i}", f"node = {b['node']}"]
        lines += [f"{k} = {_toml_number(b[k])}" + ("  # N/m" if k == "kxx" else "  # N s/m" if k == "cxx" else "")
                  for k in BEARING_COEFFICIENTS]
    for j, (n, mag, ph) in enumerate(unbalances):
        lines += ["", f"[[rotor.unbalance]]  # unbalance{j}: ROSS's magnitude {mag!r} kg m, phase {ph!r} rad",
                  f"node = {n}", f"m_u = {_toml_number(mag)}  # kg (m_u d = the magnitude)", "d = 1.0  # m",
                  f"alpha_deg = {_toml_number(math.degrees(ph))}"]
    with open(scenario, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return dofs


def _toml_string(s: str) -> str:
    out = ['"']
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ch == "\x7f":
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _values(result: Any) -> dict[str, float]:
    """Parameter name -> value from an Identification, a summary dict (its ``parameters``
    rows) or a mapping of names to values."""
    if hasattr(result, "to_dict"):
        result = result.to_dict()
    if isinstance(result, Mapping) and "parameters" in result:
        rows = result["parameters"]
        values = {str(r["parameter"]): r["value"] for r in rows}
    elif isinstance(result, Mapping):
        values = dict(result)
    else:
        raise TypeError(f"result: expected an Identification, a summary dict or a mapping of parameter names to values, got {type(result).__name__}")
    out = {}
    for name, v in values.items():
        if isinstance(v, Mapping):
            v = v.get("value")
        if v is None or not math.isfinite(float(v)):
            if str(name).startswith("bearing"):
                raise ValueError(f"result: {name} = {v} is not determined: a bearing needs a finite value of each coefficient identified")
            continue
        out[str(name)] = float(v)
    return out


def update(rotor: Any, result: Any, *, speed: float = 0.0, frequency: float | None = None) -> Any:
    """A copy of the ``ross.Rotor`` ``rotor`` whose bearings have the identified
    coefficients of ``result``: an ``Identification``, its summary dict, or a mapping of
    parameter names to values (``{"bearing0.kxx": 1.1e6, ...}``). Bearing i is
    ``rotor.bearing_elements[i]``, as :func:`export` numbered them; a coefficient
    ``result`` does not name keeps the rotor's value at ``speed`` and ``frequency``
    [rad/s]. Each new bearing is a ``ross.BearingElement`` with constant coefficients at
    the same node and tag; the shaft, disks, point masses and the rotor's settings are
    the rotor's. Unbalance parameters are ignored (a ``ross.Rotor`` holds none); a name
    ``bearing<i>.<coefficient>`` the rotor has not is a ``ValueError``.
    """
    import ross as rs

    values = _values(result)
    bearings = _bearings(rotor, float(speed), frequency)
    for name in values:
        head, _, coef = name.partition(".")
        if not head.startswith("bearing"):
            continue
        i = head[len("bearing"):]
        if not (i.isdigit() and int(i) < len(bearings) and coef in BEARING_COEFFICIENTS):
            raise ValueError(
                f"result: {name} is not a parameter of this rotor: it has bearing0 .. bearing{len(bearings) - 1}, "
                f"each with {', '.join(BEARING_COEFFICIENTS)}")
    new_bearings = []
    for i, (b, old) in enumerate(zip(bearings, rotor.bearing_elements)):
        coef = {k: values.get(f"bearing{i}.{k}", b[k]) for k in BEARING_COEFFICIENTS}
        new_bearings.append(rs.BearingElement(n=b["node"], tag=old.tag, **coef))
    p = rotor.parameters
    return rs.Rotor(
        shaft_elements=rotor.shaft_elements,
        disk_elements=rotor.disk_elements,
        bearing_elements=new_bearings,
        point_mass_elements=rotor.point_mass_elements,
        motor_element=getattr(rotor, "motor_element", None),
        min_w=p.get("min_w"),
        max_w=p.get("max_w"),
        rated_w=p.get("rated_w"),
        modal_damping_ratio=p.get("modal_damping_ratio"),
        default_damping_ratio=p.get("default_damping_ratio", 0.0),
        alpha=p.get("alpha", 0.0),
        beta=p.get("beta", 0.0),
        tag=rotor.tag,
    )
