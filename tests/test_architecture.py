"""The layers of docs/architecture.md, checked by import-linter on an installed copy and
where developers work.

The contracts are in pyproject.toml. They run on the package as a wheel installs it (into a
temporary folder), so that a subpackage missing from pyproject.toml's package list fails
here too, and with ``lint-imports`` in the environment running the tests, as a developer
runs it. The checkout maps three top-level folders into one package (core/, viewer/,
plugin_gimp/); an editable install assembles it only in strict mode (a link tree, as
packaging/test.sh installs it), where import-linter sees every subpackage.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]


def _lint_imports():
    lint = shutil.which("lint-imports", path=os.path.dirname(sys.executable)) or shutil.which("lint-imports")
    assert lint, "lint-imports is missing: pip install '.[test]' installs import-linter"
    return lint


def test_lint_imports_runs_in_this_environment():
    checked = subprocess.run([_lint_imports(), "--no-cache"], cwd=CHECKOUT, capture_output=True, text=True)
    assert "does not exist" not in checked.stdout + checked.stderr, (
        "lint-imports cannot see every subpackage of this install; a lenient editable install maps "
        "viewer/ and plugin_gimp/ where import-linter does not look: reinstall with "
        "pip install -e '.[viewer,eval,test]' --config-settings editable_mode=strict (packaging/test.sh does)\n"
        + checked.stdout[-2000:])
    assert checked.returncode == 0 and "4 kept, 0 broken" in checked.stdout, checked.stdout[-4000:]


def test_import_contracts_are_kept(tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(site),
                    str(CHECKOUT)], check=True, capture_output=True)
    checked = subprocess.run([_lint_imports(), "--no-cache", "--config", str(CHECKOUT / "pyproject.toml")], cwd=tmp_path,
                             env={**os.environ, "PYTHONPATH": str(site)}, capture_output=True, text=True)
    assert checked.returncode == 0, checked.stdout[-4000:] + checked.stderr[-2000:]
    assert "4 kept, 0 broken" in checked.stdout, checked.stdout[-2000:]


def test_the_public_api_is_imported_where_first_used():
    # `import aarecovery` imports no subpackage; each public name imports its module when
    # first read, and is that module's own object.
    code = (
        "import importlib, sys, aarecovery\n"
        "print(sorted(m for m in sys.modules if m.startswith('aarecovery.')))\n"
        "from aarecovery import *\n"
        "print(sorted(set(aarecovery.__all__) - set(dir(aarecovery))))\n"
        "for name, module in aarecovery._PUBLIC.items():\n"
        "    own = importlib.import_module('aarecovery.' + (module or name))\n"
        "    assert getattr(aarecovery, name) is (own if module is None else getattr(own, name)), name\n"
        "try:\n"
        "    aarecovery.recovr\n"
        "except AttributeError as error:\n"
        "    print(error)\n")
    lines = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.splitlines()
    assert lines == ["[]", "[]", "module 'aarecovery' has no attribute 'recovr'"]


def test_every_public_name_is_listed_once():
    import aarecovery

    assert sorted(aarecovery._PUBLIC) == sorted(set(aarecovery.__all__) - {"__version__"})
