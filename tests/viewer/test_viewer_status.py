"""The status line that says what the last recovery did, from a real engine's last plan."""

import pytest

import aarecovery
from conftest import require_viewer_extra


@pytest.fixture
def plan_line():
    require_viewer_extra()
    from aarecovery.viewer.status import plan_line
    return plan_line


@pytest.fixture
def original():
    from aarecovery.viewer.bench import make_bench_pair
    return make_bench_pair(96, 64)[0]


def test_plan_line_names_the_finding_the_strength_and_the_blend_space(plan_line, original):
    with aarecovery.Engine(backend="numpy") as engine:
        engine.set_images(original, aarecovery.filters.apply("threshold", original))
        assert plan_line(engine) is None, "nothing to say before the first run"
        engine.compute()
        line = plan_line(engine)
        plan = engine.last_plan
    assert plan.mode == "safe" and plan.strength == 1
    space = {"srgb": "sRGB", "linear": "linear light"}[plan.blend_space]
    assert line.text == f"safe: point-wise filter on hard-edged content, full strength, blend in {space}"
    assert line.detail == plan.reason


def test_plan_line_gives_the_share_of_edge_pixels_repaired_once_summarized(plan_line, original):
    filtered = aarecovery.filters.apply("threshold", original)
    with aarecovery.Engine(backend="numpy") as engine:
        engine.set_images(original, filtered)
        engine.compute()
        summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, engine.result())
        line = plan_line(engine, summary)
        assert 0 < summary.edge_share <= 1
        assert f", {summary.edge_share:.0%} of edge pixels repaired, full strength" in line.text
        engine.compute(strength=0.5)
        # The summary belongs to the previous run: no share until the new one is summarized.
        asked = plan_line(engine, summary)
    assert "edge pixels repaired" not in asked.text and "strength 0.5" in asked.text
    assert asked.detail.endswith("; strength 0.5 as asked instead")


def test_plan_line_says_f_is_kept_and_what_forcing_risks(plan_line, original):
    with aarecovery.Engine(backend="numpy") as engine:
        engine.set_images(original, aarecovery.filters.apply("blur", original))
        engine.compute()
        kept = plan_line(engine)
        assert engine.last_plan.strength == 0
        engine.compute(mode="paper")
        paper = plan_line(engine)
    assert kept.text == ("safe: F is a low-pass of O, F shown unchanged, forcing a repair risks re-sharpening the "
                         "soft edges the blur made on purpose")
    assert paper.text == "paper: the published method, full strength, blend in linear light"
