"""Command lines, save rules and pair loading (no window, no GL)."""

import shlex

import numpy as np
import pytest

import aarecovery
from aarecovery.cli import build_parser
from aarecovery.viewer.saving import default_output_path, overwrite_question
from aarecovery.viewer.settings import MODE_OPTIONS, RecoverySettings, command_line
from aarecovery.viewer.sources import PairSource, load_pair


def parse(command):
    """Parse each `aarecovery ...` step with the real command-line parser."""
    parsed = []
    for step in command.split(" && "):
        words = shlex.split(step)
        assert words[0] == "aarecovery"
        parsed.append(build_parser().parse_args(words[1:]))
    return parsed


def test_command_line_reproduces_the_parameters():
    settings = RecoverySettings.defaults().with_values(sigma_d=0.25, sigma_e=0.0199999995529, iterations=7)
    (args,) = parse(command_line(PairSource("my photo.png", "f.png"), settings, "out dir/r.png"))
    assert (args.original, args.filtered, args.output) == ("my photo.png", "f.png", "out dir/r.png")
    assert (args.sigma_d, args.sigma_e, args.iterations) == (0.25, 0.02, 7)


def test_defaults_are_the_cores():
    settings = RecoverySettings.defaults()
    assert {name: getattr(settings, name) for name in aarecovery.PARAMETERS} == {
        name: spec.default for name, spec in aarecovery.PARAMETERS.items()}
    assert settings.mode == aarecovery.MODES[0]
    (args,) = parse(command_line(PairSource("o.png", "f.png"), settings, "r.png"))
    assert all(getattr(args, name) == spec.default for name, spec in aarecovery.PARAMETERS.items())


@pytest.mark.parametrize("mode", aarecovery.MODES)
def test_command_line_selects_every_mode(mode):
    assert set(MODE_OPTIONS) == set(aarecovery.MODES)
    settings = RecoverySettings.defaults().with_values(mode=mode)
    (args,) = parse(command_line(PairSource("o.png", "f.png"), settings, "r.png"))
    assert args.paper == (mode == "paper")


def test_view_command_starts_at_the_cores_defaults():
    args = build_parser().parse_args(["view"])
    assert all(getattr(args, name) == spec.default for name, spec in aarecovery.PARAMETERS.items())


def test_command_line_for_a_built_in_filter_writes_f_first():
    source = PairSource("o.png", None, "posterize", {"steps": 5})
    steps = command_line(source, RecoverySettings.defaults(), "r.png").split(" && ")
    assert len(steps) == 2 and "posterize" in steps[0] and "steps" in steps[0]
    assert "recover o.png r-filtered.png -o r.png" in steps[1]


def test_overwrite_question_names_inputs(tmp_path):
    original, filtered = tmp_path / "o.png", tmp_path / "f.png"
    original.write_bytes(b"x")
    filtered.write_bytes(b"y")
    source = PairSource(str(original), str(filtered))
    assert overwrite_question(str(tmp_path / "new.png"), source) is None
    assert "ORIGINAL input" in overwrite_question(str(original), source)
    assert "FILTERED input" in overwrite_question(str(tmp_path / "." / "f.png"), source)
    (tmp_path / "other.png").write_bytes(b"z")
    assert overwrite_question(str(tmp_path / "other.png"), source).endswith("exists. Replace it?")
    assert default_output_path(source) == str(tmp_path / "f-recovered.png")


def test_load_pair_reports_mismatched_sizes_with_file_names(tmp_path):
    aarecovery.write_image(tmp_path / "o.png", np.zeros((8, 9, 3), np.uint8))
    aarecovery.write_image(tmp_path / "f.png", np.zeros((8, 10, 3), np.uint8))
    with pytest.raises(aarecovery.InputError, match="o.png is 9x8 but f.png is 10x8"):
        load_pair(PairSource(str(tmp_path / "o.png"), str(tmp_path / "f.png")))


def test_load_pair_with_a_built_in_filter(tmp_path):
    ramp = np.tile(np.linspace(0, 255, 16).astype(np.uint8), (4, 1))
    aarecovery.write_image(tmp_path / "o.png", ramp)
    pair = load_pair(PairSource(str(tmp_path / "o.png"), None, "threshold", {"level": 0.5}))
    assert pair.filtered.shape == ramp.shape and set(np.unique(pair.filtered)) == {0, 255}


def _scanned_page(path, quality=90):
    """A page of 11 px serif text on tinted paper, drawn at 4x, box-filtered and saved as JPEG."""
    from PIL import Image, ImageDraw, ImageFont

    from aarecovery.lab.drawings import SERIF_FONT
    page = Image.new("RGB", (512, 512), (214, 203, 170))
    draw = ImageDraw.Draw(page)
    font = ImageFont.truetype(SERIF_FONT, 44)
    for line in range(4):
        draw.text((42, 64 + 102 * line), "the quick fox jumps", font=font, fill=(35, 30, 45))
    page.resize((128, 128), Image.BOX).save(path, format="JPEG", quality=quality)


def test_a_jpeg_original_is_read_with_its_tables_as_the_command_line_reads_it(tmp_path):
    # The viewer's engine gets O's JPEG tables (LoadedPair.quantization), so it shows the R
    # that `aarecovery recover` writes for the same files: without them the plan reads the
    # compression noise from the pixels, and this page came out different (measured: 447
    # pixels, up to 46 levels).
    from aarecovery.cli import main
    from aarecovery.viewer.live_recovery import LiveRecovery
    from aarecovery.viewer.messages import MessageLog
    original, filtered, written = (str(tmp_path / name) for name in ("o.jpg", "f.png", "r.png"))
    _scanned_page(original)
    luma = aarecovery.read_image(original).astype(np.float32) @ np.float32([0.2126, 0.7152, 0.0722])
    aarecovery.write_image(filtered, np.repeat(np.where(luma > 140, 255, 0).astype(np.uint8)[..., None], 3, axis=-1))
    pair = load_pair(PairSource(original, filtered))
    assert pair.quantization and pair.quantization == aarecovery.read_quantization(original)
    assert load_pair(PairSource(filtered, filtered)).quantization is None  # a PNG has none
    with aarecovery.Engine("numpy") as engine:
        recovery = LiveRecovery(engine, MessageLog(), lambda: False)
        recovery.load(pair)
        assert recovery.update()
        shown = engine.result()
        assert "quantization tables" in engine.last_plan.reason
        without = aarecovery.recover(pair.original, pair.filtered, engine=engine)
    assert main(["recover", original, filtered, "-o", written, "--backend", "numpy"]) == 0
    assert np.array_equal(shown, aarecovery.read_image(written))
    assert not np.array_equal(shown, without)
