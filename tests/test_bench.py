"""``aarecovery bench`` runs every stage and configuration and writes its report as JSON."""

import json

import pytest

from aarecovery.cli import main
from aarecovery.lab.bench import STAGES

pytestmark = pytest.mark.gl


def test_bench_reports_stages_configurations_and_processes(tmp_path, capsys):
    report_path = tmp_path / "bench.json"
    status = main(["bench", "--sizes", "64x48", "--runs", "1", "--filters", "threshold",
                   "--configs", "gl-fragment,gl-compute,numpy", "--process", "40x32", "--json", str(report_path)])
    assert status == 0
    printed = capsys.readouterr().out
    assert "gl-compute" in printed and "MP/s" in printed
    report = json.loads(report_path.read_text())
    (row,) = report["results"]
    assert row["size"] == "64x48" and set(row["configs"]) == {"gl-fragment", "gl-compute", "numpy"}
    for stage in STAGES:
        seconds = row[f"{stage}_s"] if stage in ("decode", "plan", "encode") else row["configs"]["gl-compute"]["stages"][stage]
        assert seconds > 0, stage
    for figures in row["configs"].values():
        assert figures["paper_mps"] > 0 and figures["safe_mps"] > 0 and figures["passes_mps"] > 0
    rows = report["process"]["rows"]
    assert set(rows) == {"gl-fragment safe", "gl-fragment paper", "gl-compute safe", "gl-compute paper", "numpy safe"}
    assert all(row["peak_bytes"] > 10 * 2**20 and row["seconds"] > 0 for row in rows.values())
    assert rows["gl-fragment safe"]["ratio_to_numpy"] > 0


def test_bench_refuses_an_unknown_configuration(capsys):
    assert main(["bench", "--configs", "gl-vulkan"]) == 1
    assert "unknown configuration 'gl-vulkan'" in capsys.readouterr().err
