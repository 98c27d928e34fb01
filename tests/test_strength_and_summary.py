"""The strength control and the one-line summary of what a recovery did (API and commands)."""

import dataclasses

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.cli import main
from aarecovery.plan.forcing import forcing_advice
from scenes import disc_and_bar
from test_cli_recover import edge_pair


@pytest.fixture
def threshold_pair():
    return edge_pair(dtype=np.uint8)


@pytest.fixture
def blur_pair():
    # Edges in every direction: a lone straight edge leaves the blur kernel undetermined.
    original = np.rint(disc_and_bar()[..., :3] * 255).astype(np.uint8)
    return original, aarecovery.filters.apply("blur", original)


def test_strength_scales_the_repair_between_f_and_the_full_repair(threshold_pair, backend):
    original, filtered = threshold_pair
    with aarecovery.Engine(backend) as engine:
        engine.set_images(original, filtered)
        full = engine.recover(strength=1).astype(np.float64)
        assert engine.last_plan.strength == 1 and engine.last_plan.reason.endswith("; strength 1 as asked instead")
        none = engine.recover(strength=0)
        half = engine.recover(strength=0.5).astype(np.float64)
    np.testing.assert_array_equal(none, filtered)
    assert np.abs(full - filtered).max() > 60
    # Half the strength: about half of the change (the solve is not linear in strength).
    changed = np.abs(full - filtered) > 8
    ratio = np.abs(half - filtered)[changed].sum() / np.abs(full - filtered)[changed].sum()
    assert 0.3 < ratio < 0.7, ratio


def test_strength_forces_a_repair_where_the_safe_default_keeps_f(blur_pair, backend):
    original, filtered = blur_pair
    kept = aarecovery.recover(original, filtered, backend=backend)
    np.testing.assert_array_equal(kept, filtered)
    forced = aarecovery.recover(original, filtered, backend=backend, strength=1)
    assert np.abs(forced.astype(np.int64) - filtered).max() > 2
    paper = aarecovery.recover(original, filtered, backend=backend, mode="paper", strength=0.25)
    paper_full = aarecovery.recover(original, filtered, backend=backend, mode="paper")
    assert np.abs(paper.astype(np.int64) - filtered).sum() < np.abs(paper_full.astype(np.int64) - filtered).sum()


@pytest.mark.parametrize("value", [-0.1, 1.5, float("nan"), "1", True])
def test_a_strength_outside_0_to_1_is_refused_with_the_way_back(threshold_pair, value):
    with pytest.raises(aarecovery.InputError, match=r"strength must be a number from 0 to 1, got .*; leave it "
                                                    r"out for the strength the safe default chooses per image"):
        aarecovery.recover(*threshold_pair, backend="numpy", strength=value)


def test_summary_counts_the_changed_pixels_and_names_the_plan(threshold_pair, backend):
    original, filtered = threshold_pair
    with aarecovery.Engine(backend) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine)
        summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, recovered)
    changed = (np.abs(recovered.astype(np.int64) - filtered).max(axis=-1) >= 1).sum()
    assert summary.changed_pixels == changed > 0
    assert 0.2 < summary.edge_share <= 1
    plan = summary.plan
    assert summary.line() == (f"repaired {summary.edge_share:.0%} of the edge pixels ({changed} pixels changed) in "
                              f"safe mode ({plan.decision}): strength {plan.strength:g}, blend in {plan.blend_space}"
                              + (", pure colours of thin features" if plan.pure_colours is not None else "")
                              + (", the filter's steps antialiased across smooth gradients"
                                 if plan.ramp_table is not None else ""))


def test_summary_of_a_kept_f_says_why_and_what_forcing_risks(blur_pair):
    original, filtered = blur_pair
    with aarecovery.Engine("numpy") as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine)
        # recover kept F without running the engine, and still left the plan on it.
        summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, recovered)
    assert summary.changed_pixels == 0
    line = summary.line(force="--strength 1")
    assert summary.decision == Decision.LOWPASS_KEPT
    assert line.startswith("returned F unchanged (safe mode, lowpass-kept): F is a low-pass (blur) of O")
    assert line.endswith("; forcing a repair (--strength 1) risks re-sharpening the soft edges the blur made on "
                         "purpose")


def test_summary_of_a_float_grey_pair_counts_in_its_own_scale():
    original = edge_pair(dtype=np.uint16)[0][..., 0].astype(np.float32) / 65535
    filtered = (original > 0.5).astype(np.float32)
    recovered = aarecovery.recover(original, filtered, backend="numpy")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
    summary = aarecovery.summarize_recovery(plan, original, filtered, recovered)
    assert summary.changed_pixels == (np.abs(recovered - filtered) > 0.5 / 255).sum() > 0


@pytest.mark.parametrize("channels", [1, 4])
def test_summary_counts_16_bit_changes_above_half_an_8_bit_step(channels):
    # Half an 8-bit step is 128.5 of 65535: a change of 128 does not count, 129 does, in any
    # channel, counted in the images' own integers.
    filtered = np.full((6, 5, channels), 30000, np.uint16)
    recovered = filtered.copy()
    recovered[0, 0, -1] += 128
    recovered[1, 1, 0] -= 129
    recovered[2, 2, -1] += 129
    recovered[3, 3, 0] = 0
    if channels == 1:
        filtered, recovered = filtered[..., 0], recovered[..., 0]
    summary = aarecovery.summarize_recovery(aarecovery.Plan(sigma_d=0.1, sigma_e=0.01, iterations=3), filtered, filtered, recovered)
    assert summary.changed_pixels == 3


def test_recover_prints_the_summary_and_takes_strength(tmp_path, capsys, blur_pair):
    original, filtered = blur_pair
    aarecovery.write_image(tmp_path / "o.png", original)
    aarecovery.write_image(tmp_path / "f.png", filtered)
    assert main(["recover", str(tmp_path / "o.png"), str(tmp_path / "f.png"), "-o", str(tmp_path / "kept.png"),
                 "--backend", "numpy"]) == 0
    wrote, said = capsys.readouterr().out.splitlines()
    assert wrote.startswith(f"wrote {tmp_path / 'kept.png'}")
    assert said.startswith("returned F unchanged") and "forcing a repair (--strength 1) risks" in said
    assert main(["recover", str(tmp_path / "o.png"), str(tmp_path / "f.png"), "-o", str(tmp_path / "forced.png"),
                 "--backend", "numpy", "--strength", "1"]) == 0
    said = capsys.readouterr().out.splitlines()[1]
    assert said.startswith("repaired ") and "strength 1," in said
    forced = aarecovery.read_image(tmp_path / "forced.png")
    assert np.abs(forced.astype(np.int64) - filtered).max() > 2


def test_filter_recover_prints_the_summary_and_strength_needs_recover(tmp_path, capsys, threshold_pair):
    aarecovery.write_image(tmp_path / "o.png", threshold_pair[0])
    assert main(["filter", "threshold", str(tmp_path / "o.png"), "-o", str(tmp_path / "r.png"), "--recover",
                 "--strength", "0.5", "--backend", "numpy"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == f"wrote {tmp_path / 'r.png'}" and "strength 0.5," in lines[1]
    assert main(["filter", "threshold", str(tmp_path / "o.png"), "-o", str(tmp_path / "t.png"),
                 "--strength", "0.5"]) == 1
    assert "--strength only applies with --recover" in capsys.readouterr().err
    assert not (tmp_path / "t.png").exists()


@pytest.mark.parametrize("errors, helps", [({0.0: 1.0, 0.25: 0.995, 0.5: 1.02, 1.0: 1.3, 0.125: 0.996}, True),
                                           ({0.0: 1.0, 0.25: 1.1, 0.5: 1.3, 1.0: 1.6, 0.125: 1.04}, False)])
def test_the_force_is_offered_only_where_the_calibration_saw_it_help(errors, helps):
    forcing = forcing_advice(Decision.POINTWISE_CALIBRATED, errors=errors)
    assert forcing.helps == helps
    plan = aarecovery.Plan(0.1, 0.01, 3, strength=0.0, mode="safe", reason="calibration chose strength 0",
                           decision=Decision.POINTWISE_CALIBRATED, forcing=forcing)
    line = aarecovery.RecoverySummary(plan, 0, 0.0).line(force="--strength 1")
    if helps:
        assert line.endswith("a forced repair may help (at half resolution strength 0.25 was 0.5% closer than F, "
                             "too little to choose it): use --strength 1")
    else:
        assert line.endswith("forcing a repair (--strength 1) risks a result farther from the truth than F: at half "
                             "resolution every strength tried was worse than F (strength 1 by 60%)")


def test_an_unsharp_masked_photo_is_not_offered_the_force():
    """The issue's portrait: forced to full strength, its irises went grey with pale halos.
    It is repaired at a photo's low strength, and nothing offers more."""
    from aarecovery.lab import scenes as _scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(_scenes.render("astronaut", 64, 4), "unsharp", 4, "linear")
    with aarecovery.Engine("numpy") as engine:
        recovered = aarecovery.recover(case.original, case.filtered, engine=engine)
        summary = aarecovery.summarize_recovery(engine.last_plan, case.original, case.filtered, recovered)
    assert summary.decision == Decision.NEIGHBOURHOOD_TEXTURED
    line = summary.line(force="--strength 1")
    assert "--strength 1" not in line and "strength 0.1," in line, line


def test_a_smoothed_photo_says_what_forcing_risks():
    from aarecovery.lab import scenes as _scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(_scenes.render("astronaut", 64, 4), "bilateral", 4, "linear")
    with aarecovery.Engine("numpy") as engine:
        recovered = aarecovery.recover(case.original, case.filtered, engine=engine)
        summary = aarecovery.summarize_recovery(engine.last_plan, case.original, case.filtered, recovered)
    assert summary.decision == Decision.NEIGHBOURHOOD_TEXTURED_KEPT
    assert "use --strength 1" not in summary.line(force="--strength 1")
    assert "risks flattening the photo's texture" in summary.line(force="--strength 1")


def test_the_advice_holds_where_f_was_exact_at_half_resolution():
    # The calibration's error at strength 0 can be exactly 0 (a table that commutes with the
    # box filter on the edges it read); the advice divided by it.
    forcing = forcing_advice(Decision.POINTWISE_HARD_EDGED_GRAINED, errors={0.0: 0.0, 0.25: 1e-6, 0.5: 4e-6,
                                                                          1.0: 1e-5, 0.125: 2e-7})
    assert not forcing.helps and "F was exact" in forcing.why


def test_a_repair_within_the_models_error_says_so():
    forcing = forcing_advice(Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT, ratio=1.19)
    assert not forcing.helps and "repair-to-error ratio 1.19" in forcing.why


def test_the_summary_reads_the_window_the_plan_analysed(backend):
    # Larger than the analysis window, with its edges in a corner: the window is chosen.
    original, filtered = (np.zeros((700, 900, 3), np.uint8) for _ in range(2))
    original[560:, 700:], filtered[560:, 700:] = edge_pair(140, 200, np.uint8)
    with aarecovery.Engine(backend) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine)
        window = aarecovery.sample.array_window(original)
        assert engine.last_plan.window == window != aarecovery.sample.analysis_windows(700, 900)[0]
        engine.set_images(original, filtered)
        assert engine.plan().window == window
    summary = aarecovery.summarize_recovery(engine.last_plan, original, filtered, recovered)
    chosen_again = aarecovery.summarize_recovery(dataclasses.replace(engine.last_plan, window=None), original,
                                                 filtered, recovered)
    assert summary.line() == chosen_again.line()
    assert (summary.changed_pixels, summary.edge_share) == (chosen_again.changed_pixels, chosen_again.edge_share)
    assert summary.changed_pixels > 0 and summary.edge_share > 0.05


def test_the_summary_from_the_window_of_o_alone_is_the_whole_ones(backend):
    """The command line keeps only O's analysis window for the summary and frees the rest
    before it encodes R (its peak memory was there): the same summary."""
    original, filtered = (np.zeros((700, 900, 3), np.uint8) for _ in range(2))
    original[560:, 700:], filtered[560:, 700:] = edge_pair(140, 200, np.uint8)
    original[40:180, 60:260], filtered[40:180, 60:260] = edge_pair(140, 200, np.uint8)
    with aarecovery.Engine(backend) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine)
    plan = engine.last_plan
    whole = aarecovery.summarize_recovery(plan, original, filtered, recovered)
    windowed = aarecovery.summarize_recovery(plan, None, filtered, recovered, original_window=original[plan.window])
    assert windowed == whole and whole.edge_share > 0.05
    with pytest.raises(ValueError, match="needs the plan's window"):
        aarecovery.summarize_recovery(dataclasses.replace(plan, window=None), None, filtered, recovered,
                                      original_window=original[plan.window])


def test_the_command_line_summary_is_the_apis(tmp_path, capsys):
    original, filtered = (np.zeros((700, 900, 3), np.uint8) for _ in range(2))
    original[560:, 700:], filtered[560:, 700:] = edge_pair(140, 200, np.uint8)
    aarecovery.write_image(tmp_path / "o.png", original)
    aarecovery.write_image(tmp_path / "f.png", filtered)
    assert main(["recover", str(tmp_path / "o.png"), str(tmp_path / "f.png"), "-o", str(tmp_path / "r.png"),
                 "--backend", "numpy"]) == 0
    printed = capsys.readouterr().out.splitlines()[-1]
    with aarecovery.Engine("numpy") as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine)
        expected = aarecovery.summarize_recovery(engine.last_plan, original, filtered, recovered)
    assert printed == expected.line(force="--strength 1")
