"""The layers of docs/architecture.md, checked by import-linter on an installed copy.

The contracts are in pyproject.toml. They run on the package as a wheel installs it (into a
temporary folder), because the checkout maps three top-level folders into one package
(core/, viewer/, plugin_gimp/), which only an install assembles; a subpackage missing from
pyproject.toml's package list therefore fails here too.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]


def test_import_contracts_are_kept(tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(site),
                    str(CHECKOUT)], check=True, capture_output=True)
    lint = shutil.which("lint-imports", path=os.path.dirname(sys.executable)) or shutil.which("lint-imports")
    assert lint, "lint-imports is missing: pip install '.[test]' installs import-linter"
    checked = subprocess.run([lint, "--no-cache", "--config", str(CHECKOUT / "pyproject.toml")], cwd=tmp_path,
                             env={**os.environ, "PYTHONPATH": str(site)}, capture_output=True, text=True)
    assert checked.returncode == 0, checked.stdout[-4000:] + checked.stderr[-2000:]
    assert "4 kept, 0 broken" in checked.stdout, checked.stdout[-2000:]
