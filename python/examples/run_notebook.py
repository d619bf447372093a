"""Executes rheometer.ipynb with nbclient (CI: it must run without error); the executed copy
goes to target/notebook/rheometer.executed.ipynb, the source is left as it is."""
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

here = Path(__file__).resolve().parent
root = here.parents[1]
nb = nbformat.read(here / "rheometer.ipynb", as_version=4)
t0 = time.time()
NotebookClient(nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(here)}}).execute()
out = root / "target" / "notebook"
out.mkdir(parents=True, exist_ok=True)
nbformat.write(nb, out / "rheometer.executed.ipynb")
print(f"notebook executed in {time.time() - t0:.1f} s: {len(nb.cells)} cells, no error")
