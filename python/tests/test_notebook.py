"""The example notebook runs from start to end: photo → SPD → plot → metrics."""

import nbformat
from nbclient import NotebookClient

from conftest import ROOT


def test_the_example_notebook_runs():
    path = ROOT / "examples" / "spdcam.ipynb"
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(
        notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
    ).execute()
    outputs = [o for c in notebook.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    text = "".join(o.get("text", "") for o in outputs)
    assert "ColorChecker Digital SG detected" in text
    assert "GFC against the truth" in text and "CIE Ra" in text
    assert not [o for o in outputs if o.get("output_type") == "error"]
