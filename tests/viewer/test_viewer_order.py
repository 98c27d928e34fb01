"""The viewer says so when the pair it opened looks swapped: a message and a status line."""

import numpy as np
import pytest

from conftest import require_viewer_extra

pytestmark = pytest.mark.usefixtures("xvfb_display")


def test_swapped_pair_is_flagged(tmp_path):
    require_viewer_extra()
    import aarecovery
    from aarecovery.lab import scenes
    from aarecovery.lab.groundtruth import make_case
    from aarecovery.viewer.app import ViewerApp
    from aarecovery.viewer.sources import PairSource
    from aarecovery.viewer.status import status_lines

    case = make_case(scenes.render("text", 96, 4), "threshold", 4)
    for name, image in (("o.png", case.original), ("f.png", case.filtered)):
        aarecovery.write_image(tmp_path / name, np.rint(image * 255).astype(np.uint8))
    app = ViewerApp(None, size=(700, 480), vsync=False)
    try:
        assert app.opener.open(PairSource(str(tmp_path / "o.png"), str(tmp_path / "f.png")))
        assert not any("swapped" in line.text for line in status_lines(app))
        assert app.opener.open(PairSource(str(tmp_path / "f.png"), str(tmp_path / "o.png")))
        assert app.step()
        assert any(message.error and "look swapped" in message.text for message in app.messages)
        assert "ORIGINAL and FILTERED look swapped" in [line.text for line in status_lines(app)]
    finally:
        app.close()
