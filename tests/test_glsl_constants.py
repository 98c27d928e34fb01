"""Each constant of the recovery exists once per language: the GLSL copy must equal the NumPy one."""

import re

import numpy as np
import pytest

from aarecovery import colour
from aarecovery.backends.gl import backend, blocks
from aarecovery.backends.gl.glsl import read_source
from aarecovery.spec import blend_model, local_plan, pure_colours, ramp_lookup, working_space

# (shader file, GLSL name) -> the value the NumPy specification uses.
TWINS = {
    ("pure_colours.glsl", "PALETTE_TOLERANCE"): pure_colours.PALETTE_TOLERANCE,
    ("pure_colour_blocks.glsl", "LINE_TOLERANCE"): pure_colours.LINE_TOLERANCE,
    ("pure_colours.glsl", "RIDGE_MARGIN"): pure_colours.RIDGE_MARGIN,
    ("pure_colours.glsl", "INK_LINE_TOLERANCE"): pure_colours.INK_LINE_TOLERANCE,
    ("pure_colours.glsl", "RIDGE_NOISE_MARGIN"): pure_colours.RIDGE_NOISE_MARGIN,
    ("pure_colours.glsl", "EXPLAIN_TOLERANCE"): pure_colours.EXPLAIN_TOLERANCE,
    ("pure_colours.glsl", "ON_LINE_TOLERANCE"): pure_colours.ON_LINE_TOLERANCE,
    ("pure_colours.glsl", "KEPT_CONTRAST"): pure_colours.KEPT_CONTRAST,
    ("pure_colours.glsl", "RANGE_TOLERANCE"): pure_colours.RANGE_TOLERANCE,
    ("pure_colours.glsl", "END_TOLERANCE"): pure_colours.END_TOLERANCE,
    ("pure_colours.glsl", "MIN_CONTRAST"): pure_colours.MIN_CONTRAST,
    ("pure_colours.glsl", "MIN_REACH"): pure_colours.MIN_REACH,
    ("pure_colours.glsl", "INK_TOLERANCE"): pure_colours.INK_TOLERANCE,
    ("pure_colours.glsl", "SHORT_REACH"): pure_colours.SHORT_REACH,
    ("pure_colours.glsl", "RIDGE_EDGE_SCALE"): pure_colours.RIDGE_EDGE_SCALE,
    ("transfer_table.glsl", "OPENCV_Y"): pure_colours._OPENCV_Y,
    ("transfer_table.glsl", "PILLOW_Y"): pure_colours._PILLOW_Y,
    ("transfer_table.glsl", "REC601_Y"): pure_colours._REC601_Y,
    ("ramp_lookup.glsl", "RAMP_SAMPLES"): ramp_lookup.RAMP_SAMPLES,
    ("ramp_lookup.glsl", "RAMP_BEND"): ramp_lookup.RAMP_BEND,
    ("local_plan.glsl", "FLAT_SPAN"): local_plan.FLAT_SPAN,
    ("local_plan.glsl", "REGION_RADIUS"): local_plan.REGION_RADIUS,
    ("local_plan.glsl", "TEXTURED_SHARE"): local_plan.TEXTURED_SHARE,
    ("local_plan.glsl", "HARD_EDGED_SHARE"): local_plan.HARD_EDGED_SHARE,
    ("local_plan.glsl", "INK_RADIUS"): local_plan.INK_RADIUS,
    ("local_plan.glsl", "INK_REPEATS"): local_plan.INK_REPEATS,
    ("local_plan.glsl", "INK_NEAR_SPAN"): local_plan.INK_NEAR_SPAN,
    ("local_plan.glsl", "INK_DARK"): local_plan.INK_DARK,
    ("local_plan.glsl", "KEPT_CONTRAST_LOW"): local_plan.KEPT_CONTRAST_LOW,
    ("local_plan.glsl", "STEEPENED_CONTRAST_HIGH"): local_plan.STEEPENED_CONTRAST_HIGH,
    ("local_plan.glsl", "KEPT_CONTRAST_HIGH"): local_plan.KEPT_CONTRAST_HIGH,
    ("local_plan.glsl", "INK_TIE"): local_plan.INK_TIE,
    ("local_plan.glsl", "INK_GATE_SHARE_LOW"): local_plan.INK_GATE_SHARE_LOW,
    ("local_plan.glsl", "INK_GATE_SHARE_HIGH"): local_plan.INK_GATE_SHARE_HIGH,
    ("local_plan.glsl", "INK_GATE_REPEATS"): local_plan.INK_GATE_REPEATS,
    ("working.glsl", "VISIBLE_COVERAGE"): working_space.VISIBLE_COVERAGE,
    ("blend_model.glsl", "TINY"): float(blend_model._TINY),
    ("blend_model.glsl", "FAINT"): float(blend_model._FAINT),
    ("blend_model.glsl", "SPREAD_TIE"): float(blend_model.SPREAD_TIE),
    ("blend_model.glsl", "SPREAD_TIE_FLOOR"): float(blend_model.SPREAD_TIE_FLOOR),
    ("blend_model.glsl", "UNTOUCHED_EXTREMES"): float(blend_model.UNTOUCHED_EXTREMES),
    ("blend_model.glsl", "BEST_PAIR_MISS"): blend_model.BEST_PAIR_MISS,
    ("blend_model.glsl", "BEST_PAIR_GAIN"): blend_model.BEST_PAIR_GAIN,
    ("blend_model.glsl", "BEST_PAIR_SPAN"): blend_model.BEST_PAIR_SPAN,
    ("blend_model.glsl", "BEST_PAIR_COVERAGE"): blend_model.BEST_PAIR_COVERAGE,
    ("blend_model.glsl", "BEST_PAIR_TIE"): blend_model.BEST_PAIR_TIE,
    ("blend_model.glsl", "BEST_PAIR_TIE_FLOOR"): blend_model.BEST_PAIR_TIE_FLOOR,
    ("classify_blocks.comp", "MARGIN"): blocks.MARGIN,
    ("classify_blocks.comp", "BLOCK_SIDE"): blocks.BLOCK_SIDE,
    ("classify_blocks.frag", "MARGIN"): blocks.MARGIN,
    ("classify_blocks.frag", "BLOCK_SIDE"): blocks.BLOCK_SIDE,
    ("live_blocks.glsl", "LIVE_BLOCK_SIDE"): blocks.BLOCK_SIDE,
    ("pure_colour_blocks.glsl", "RIDGE_BOUND_SLACK"): pure_colours.RIDGE_BOUND_SLACK,
    ("flag_wakes.comp", "BLOCK_SIDE"): blocks.BLOCK_SIDE,
    ("flag_wakes.comp", "MARGIN"): blocks.MARGIN,
    ("flag_wakes.comp", "WAKE_RIDGE"): blocks.WAKE_RIDGE,
    ("flag_wakes.comp", "FIT_PLAIN"): blocks.FIT_PLAIN,
    ("flag_wakes.comp", "FIT_WHOLE"): blocks.FIT_WHOLE,
    ("pure_colour_blocks.glsl", "WAKE_FILTERED"): blocks.WAKE_FILTERED,
    ("pure_colour_blocks.glsl", "WAKE_RIDGE"): blocks.WAKE_RIDGE,
    ("block_lists.glsl", "DRAW_COMMAND_WORDS"): blocks.DRAW_COMMAND_WORDS,
    ("block_lists.glsl", "DISPATCH_COMMAND_WORDS"): blocks.DISPATCH_COMMAND_WORDS,
    ("block_lists.glsl", "LIST_ACTIVE"): blocks.LISTS.index("active"),
    ("block_lists.glsl", "LIST_DILATED"): blocks.LISTS.index("dilated"),
    ("block_lists.glsl", "LIST_INACTIVE"): blocks.LISTS.index("inactive"),
    ("block_lists.glsl", "LIST_COUNT"): len(blocks.LISTS),
}


def _constant(source, name):
    match = re.search(rf"const\s+\w+\s+{name}\s*=\s*([^;]+);", source)
    assert match, f"no constant {name}"
    value = re.sub(r"(\d)u\b", r"\1", match.group(1))  # unsigned literals
    return eval(re.sub(r"vec[34]", "tuple", value), {"tuple": lambda *v: v})  # numbers and a / b only


@pytest.mark.parametrize("file, name", sorted(TWINS))
def test_glsl_constant_equals_numpy_twin(file, name):
    assert np.array_equal(np.float32(_constant(read_source(file), name)), np.float32(TWINS[file, name]))


def test_luma_weights_are_the_same_in_glsl():
    assert _constant(read_source("colour.glsl"), "LUMA") == colour.LUMA


def test_palette_array_holds_the_palette_size():
    assert f"uniform vec3 palette[{pure_colours.PALETTE_SIZE}];" in read_source("pure_colours.glsl")


def test_the_longest_ink_loop_holds_the_ink_count():
    # The array and its loop are INK_SLOTS long, one of the backend's compiled lengths.
    assert "uniform vec3 inks[INK_SLOTS];" in read_source("pure_colours.glsl")
    assert max(backend._INK_SLOT_COUNTS) == pure_colours.INK_COUNT


def test_em_iterations_match():
    assert f"iteration < {blend_model._EM_ITERATIONS};" in read_source("blend_model.glsl")


def test_compute_block_side_matches():
    # A define there: GLSL 4.30 takes only literals in a work group's size.
    assert f"#define BLOCK_SIDE {blocks.BLOCK_SIDE} " in read_source("compute.glsl")
