"""The evaluation in quick mode, and the safe default's quality thresholds asserted on it."""

import numpy as np
import pytest

from aarecovery.lab import evaluate as _eval
from aarecovery.lab import report as _report
from aarecovery.lab.metrics import edge_band, error_reduction, psnr, ssim
from aarecovery.lab.peers import PEERS


@pytest.fixture(scope="module")
def quick():
    results, missing = _eval.run_suite(_eval.QUICK, backend="numpy")
    return results, missing, _eval.summarize(results)


def test_metrics_on_known_values():
    a = np.zeros((8, 8, 3), np.float32)
    b = a + np.float32(0.1)
    assert psnr(a, b) == pytest.approx(20.0, abs=1e-4)
    assert psnr(a, a) == 100.0
    assert ssim(a, a) == pytest.approx(1.0)
    assert ssim(a, b) < 1.0
    mask = np.zeros((8, 8), bool)
    mask[2, 2] = True
    c = a.copy()
    c[2, 2] = 0.05
    assert error_reduction(c, b, a, mask) == pytest.approx(1 - 0.25, abs=1e-6)


def test_edge_band_covers_changes_and_original_edges():
    o = np.zeros((10, 10, 3), np.float32)
    o[:, 5:] = 1
    band = edge_band(o, o, o)
    assert band[:, 3:7].all() and not band[:, :2].any()
    reference = o.copy()
    reference[0, 0] = 0.5
    assert edge_band(o, o, reference)[:2, :2].all()


def test_quick_suite_covers_every_filter_scene_and_method(quick):
    results, missing, _ = quick
    names = {r.filter_name for r in results}
    assert names == set(_eval.QUICK.filters)
    assert {r.scene for r in results} == set(_eval.QUICK.scenes)
    for r in results:
        assert {"F", "R", "paper"} <= set(r.psnr_band)
        assert {p.name for p in PEERS if p not in missing} <= set(r.psnr_band)


def test_missing_peers_are_reported_loudly():
    results = [_eval.CaseResult("text", "linear", "threshold", "synthetic",
                                psnr={"F": 10, "R": 12}, ssim={"F": 0.5, "R": 0.6},
                                psnr_band={"F": 10, "R": 12}, ssim_band={"F": 0.5, "R": 0.6},
                                reduction={"R": 0.3})]
    table = _report.format_table(results, missing=PEERS)
    assert table.count("NOT installed") == len(PEERS)
    assert "gegl" in table and "gmic" in table


def test_peers_are_installed_in_ci(quick):
    # packaging/test.sh installs the Debian packages gegl and gmic; the comparison is part of the product.
    _, missing, _ = quick
    assert not missing, f"peer tools missing: {[p.package for p in missing]}"


def test_safe_default_never_loses_more_than_a_tenth_of_a_db(quick):
    _, _, summary = quick
    loss, where = summary["worst_loss_db"]
    assert loss <= _eval.MAX_LOSS_DB, f"R is {loss:.2f} dB worse than F on {where}"


def test_safe_default_beats_gimp_and_gmic_on_every_filter_but_blur(quick):
    _, missing, summary = quick
    if missing:
        pytest.skip("peer tools not installed (see test_peers_are_installed_in_ci)")
    losing = [name for name, beats in summary["beats_peers"].items() if not beats]
    assert not losing, f"R does not beat both peers on: {losing}"


def test_mean_error_reduction_floor(quick):
    # Regression floor below the measured values (linear 0.766, srgb 0.781 on the quick suite
    # on 2026-11-24; `aarecovery eval --quick` prints today's,
    # with the pure colours of thin features and the luma-scale tables of tone mapping and
    # equalization, the power-law ends of the table, and O's darkest/brightest colour kept pure
    # between thin lines) minus a margin; the paper's method measures 0.600 and 0.409.
    _, _, summary = quick
    for space, values in summary["mean_reduction"].items():
        assert values["R"] >= 0.66, f"{space}: {values}"


def test_mean_error_reduction_reaches_the_target(quick):
    # Target of issue 3: mean edge-band error reduction >= 0.75 on synthetic scenes, blur
    # excluded, for both kinds of antialiasing. Measured 0.766 (linear) and 0.781 (srgb) on
    # the quick suite on 2026-11-24 (`aarecovery eval --quick` prints today's); full suite
    # 0.794 and 0.806.
    _, _, summary = quick
    assert set(summary["mean_reduction"]) == {"linear", "srgb"}
    for space, values in summary["mean_reduction"].items():
        assert values["R"] >= _eval.MIN_MEAN_REDUCTION, f"{space}: {values}"


def test_table_and_report_are_written(tmp_path):
    suite = _eval.Suite(("shapes",), ("threshold", "blur"), 32)
    results, missing = _eval.run_suite(suite, backend="numpy", peers=False, keep_images=True)
    table = _report.format_table(results, missing)
    assert "== threshold" in table and "== blur" in table and "worst edge-band loss" in table
    path = _report.write_report(results, str(tmp_path), missing)
    text = open(path, encoding="utf-8").read()
    assert "threshold-crop.png" in text
    from PIL import Image
    with Image.open(tmp_path / "threshold-crop.png") as crop:
        assert crop.size[0] > 32 * 6 * 4


def test_eval_command_runs(capsys):
    from aarecovery.cli import main
    assert main(["eval", "--scenes", "star", "--filters", "posterize", "--width", "32", "--no-peers"]) == 0
    out = capsys.readouterr().out
    assert "== posterize" in out and "star" in out


def test_the_summary_names_its_suite(quick, capsys):
    results, missing, _ = quick
    table = _report.format_table(results, missing, "the quick suite")
    summary = [line for line in table.splitlines() if line.startswith("mean edge-band error reduction")]
    assert len(summary) == 2 and all(" on the quick suite, " in line and "(paper " in line for line in summary)
    from aarecovery.cli import main
    assert main(["eval", "--no-peers", "--scenes", "text", "--filters", "threshold"]) == 0
    assert "on a custom suite (1 scenes, 1 filters, 128 px, k=4)" in capsys.readouterr().out


def test_readme_leaves_the_quick_suite_figures_to_the_command():
    """The README's quick-suite figures went stale (0.780 / 0.761 where eval --quick printed
    0.766 / 0.781): it names the command that prints them instead of copying them."""
    import re
    from pathlib import Path
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme.split("## How well it works", 1)[1].split("\n## ", 1)[0]
    sentences = re.split(r"(?<=[.;])\s", " ".join(section.split()))
    quick = [sentence for sentence in sentences if "quick suite" in sentence]
    assert quick and any("aarecovery eval --quick" in sentence for sentence in quick), quick
    assert not any(re.search(r"\b0\.\d{3}\b", sentence) for sentence in quick), quick
