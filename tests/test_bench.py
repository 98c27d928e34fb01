"""``aarecovery bench`` runs every stage and configuration and writes its report as JSON."""

import json
import shutil

import numpy as np
import pytest

from aarecovery.cli import main
from aarecovery.lab.bench import STAGES

pytestmark = pytest.mark.gl


def test_bench_reports_stages_and_configurations(tmp_path, capsys):
    report_path = tmp_path / "bench.json"
    status = main(["bench", "--sizes", "64x48", "--runs", "1", "--filters", "threshold",
                   "--configs", "gl-fragment,gl-compute,numpy", "--json", str(report_path)])
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


def test_bench_process_times_whole_processes_and_prints_their_ratios(capsys):
    # Both kinds of pair, small: every command runs file to file; gegl only where installed.
    status = main(["bench", "--process", "96", "--runs", "1", "--json"])
    assert status == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)  # stdout is the JSON report alone
    gegl = shutil.which("gegl") is not None
    pairs = report["process"]["pairs"]
    assert [pair["pair"] for pair in pairs] == ["thin", "photo"]
    for pair in pairs:
        assert pair["size"] == "96x96"
        assert set(pair["rows"]) == {"safe", "paper", "numpy-paper"} | ({"gegl"} if gegl else set())
        assert all(row["peak_bytes"] > 10 * 2**20 and row["seconds"] > 0 for row in pair["rows"].values())
        assert set(pair["ratios"]) == {"safe/paper", "numpy-paper/safe"} | ({"safe/gegl"} if gegl else set())
        assert all(ratio > 0 for ratio in pair["ratios"].values())
        assert set(pair["cpu_ratios"]) == set(pair["ratios"]) and all(row["cpu_seconds"] > 0
                                                                       for row in pair["rows"].values())
    assert captured.err.count("  ratios: safe/paper") == 2 and captured.err.count("CPU-time ratios: safe/paper") == 2
    assert gegl or "gegl:antialias skipped" in captured.err


def test_the_thin_features_pair_makes_the_safe_default_pick_pure_colours():
    from aarecovery.lab.processes import thin_features_pair
    from aarecovery.params import Parameters
    from aarecovery.plan import make_plan
    original, filtered = thin_features_pair(256, 256)
    assert make_plan(original, filtered, Parameters()).pure_colours is not None


def test_the_numpy_yardstick_is_the_papers_method():
    # Written independently of the specification, it gives the paper mode's result.
    import aarecovery
    from aarecovery.lab.bench import bench_image_pair
    from aarecovery.lab.paper_numpy import recover_paper
    original, filtered = bench_image_pair(64, 48)
    expected = aarecovery.recover(original, filtered, backend="numpy", mode="paper")
    assert (expected != filtered).any()
    assert np.abs(recover_paper(original, filtered).astype(np.int64) - expected).max() <= 1


def test_bench_refuses_an_unknown_configuration(capsys):
    assert main(["bench", "--configs", "gl-vulkan"]) == 1
    assert "unknown configuration 'gl-vulkan'" in capsys.readouterr().err


def test_bench_process_without_numpy_runs_leaves_the_numpy_program_out(capsys):
    status = main(["bench", "--process", "64", "--runs", "1", "--pairs", "photo", "--numpy-runs", "0", "--json"])
    assert status == 0
    (pair,) = json.loads(capsys.readouterr().out)["process"]["pairs"]
    assert "numpy-paper" not in pair["rows"] and "numpy-paper/safe" not in pair["ratios"]
    assert {"safe", "paper"} <= set(pair["rows"]) and "safe/paper" in pair["ratios"]


def test_bench_passes_times_each_gl_pass_on_its_own(capsys):
    # Every pass of each mode, labelled, waited for: the device's time per pass (issue 21's
    # "what bounds each figure" on a GPU, where issuing the passes costs more than running them).
    status = main(["bench", "--sizes", "96x64", "--runs", "1", "--filters", "gamma", "--configs",
                   "gl-compute,numpy", "--passes", "--json"])
    assert status == 0
    captured = capsys.readouterr()
    (row,) = json.loads(captured.out)["results"]
    passes = row["configs"]["gl-compute"]["passes_ms"]
    assert set(passes) == {"paper", "safe"}
    assert {"classify", "fit_blend_model", "jacobi_step", "jacobi_step (final)"} <= set(passes["paper"])
    assert all(value > 0 for value in passes["paper"].values())
    assert "passes_ms" not in row["configs"]["numpy"]
    assert "gl-compute paper, each pass waited for (ms): classify" in captured.err
