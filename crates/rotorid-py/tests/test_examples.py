"""The quickstart notebook runs (and is stored without outputs); the Dask example
identifies a folder of records in parallel."""

from __future__ import annotations

import importlib.util
import json

import nbformat
from nbclient import NotebookClient

import rotorid
from conftest import EXAMPLES


def test_quickstart_notebook_runs_and_is_stored_stripped():
    path = EXAMPLES / "quickstart.ipynb"
    stored = json.loads(path.read_text())
    for cell in stored["cells"]:
        if cell["cell_type"] == "code":
            assert cell["outputs"] == [] and cell["execution_count"] is None, "strip the outputs"
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": str(EXAMPLES)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    html = [o for o in outputs if "text/html" in o.get("data", {})]
    assert any("rotorid refine" in o["data"]["text/html"] for o in html)
    assert any("image/png" in o.get("data", {}) for o in outputs)


def test_dask_example_identifies_a_folder(tmp_path, table1):
    for seed in range(3):
        df = rotorid.simulate(table1, snr_db=40, seed=seed, duration=0.3)
        df.to_csv(tmp_path / f"run{seed}.csv", index=False)
    spec = importlib.util.spec_from_file_location("dask_folder", EXAMPLES / "dask_folder.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    table = mod.identify_folder(tmp_path, "table1", "refine", workers=2)
    assert list(table.index) == ["run0.csv", "run1.csv", "run2.csv"]
    assert set(table.columns) >= {"m", "m_std", "kx", "kz", "warnings"}
    assert ((table["m"] / 14.29 - 1).abs() < 1e-2).all()
    assert (table["warnings"] == 0).all()
