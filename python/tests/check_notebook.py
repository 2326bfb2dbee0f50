"""Runs docs/python_tour.ipynb headless with nbconvert and checks that its cells ran and drew their images."""
import json
import os
import subprocess
import sys
import tempfile

root = os.environ.get("ALGRAY_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
notebook = os.path.join(root, "docs", "python_tour.ipynb")
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "executed.ipynb")
    subprocess.run(["jupyter-nbconvert", "--to", "notebook", "--execute", "--ExecutePreprocessor.timeout=300",
                    "--output", out, notebook], check=True, cwd=os.path.dirname(notebook))
    cells = json.load(open(out))["cells"]
code = [c for c in cells if c["cell_type"] == "code"]
errors = [o for c in code for o in c["outputs"] if o["output_type"] == "error"]
pngs = sum("image/png" in o.get("data", {}) for c in code for o in c["outputs"])
print(f"{len(code)} code cells ran, {pngs} PNG outputs, {len(errors)} errors")
# The torus shown by itself, three surfaces side by side, the probe's plot and the sweep.
if errors or pngs < 4 or any(c.get("execution_count") is None for c in code):
    sys.exit(1)
