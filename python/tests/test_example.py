"""examples/quickstart.py runs (Agg backend, a small image) and writes its
plot; its contrast is the one computed here from the Dataset."""

import subprocess
import sys

from conftest import ROOT


def test_quickstart_runs(tmp_path):
    p = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "quickstart.py"), str(tmp_path), "96"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0, p.stderr
    assert "runway" in p.stdout and "contrast" in p.stdout
    png = tmp_path / "quickstart.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
