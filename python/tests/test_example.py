"""examples/quickstart.ipynb runs (executed with nbclient in the project's
environment, matplotlib's Agg backend, a small image) and writes its plot
and the runway/grass contrast."""

import os

import nbclient
import nbformat

from conftest import ROOT


def test_quickstart_notebook_runs(tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = nbformat.read(ROOT / "examples" / "quickstart.ipynb", as_version=4)
    setup = nb.cells[1]
    assert "SIZE = 256" in setup.source and 'OUT = ROOT / "out"' in setup.source
    setup.source = setup.source.replace("SIZE = 256", "SIZE = 96").replace(
        'OUT = ROOT / "out"', f"OUT = Path({str(tmp_path)!r})"
    )
    client = nbclient.NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(ROOT / "examples")}}
    )
    client.execute()
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    assert "runway" in text and "contrast" in text, text
    png = tmp_path / "quickstart.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(png) > 1000
