"""Screenshot of the plug-in's dialog for docs/gimp.md, taken from GIMP 3 under Xvfb.

Run as root after ``packaging/gimp-sandbox.sh``::

    .venv/bin/python tests/gimp/dialog_screenshot.py [docs/images/gimp-dialog.png]

It starts Xvfb and the GUI ``gimp-3.0`` inside the trixie root, and opens a test image.
Then it calls the apply-filter entry interactively, grabs the dialog window with ``xwd``, and
writes a PNG. This also checks that the interactive code path builds its dialog without error.
"""

import shutil
import struct
import sys
import textwrap
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).parent))
import sandbox  # noqa: E402
from test_gimp_plugin import scene, write_png  # noqa: E402

TITLE = "Antialiasing Recovery (apply filter)..."


def xwd_to_array(data):
    """Decode a 24/32-bit TrueColor XWD dump (what xwd writes for Xvfb) into RGB uint8."""
    fields = struct.unpack(">25I", data[:100])
    header_size, width, height = fields[0], fields[4], fields[5]
    byte_order, bpp, bytes_per_line, ncolors = fields[7], fields[11], fields[12], fields[19]
    if bpp not in (24, 32):
        raise ValueError(f"unsupported XWD: {bpp} bits per pixel")
    n = bpp // 8
    start = header_size + 12 * ncolors
    rows = np.frombuffer(data[start:start + bytes_per_line * height], np.uint8)
    pixels = rows.reshape(height, bytes_per_line)[:, :width * n].reshape(height, width, n)
    return pixels[..., [2, 1, 0]] if byte_order == 0 else pixels[..., [n - 3, n - 2, n - 1]]


def main(out="docs/images/gimp-dialog.png"):
    missing = sandbox.missing_piece()
    if missing:
        sys.exit(f"{missing}; build it with: {sandbox.BUILD_HINT}")
    with sandbox.Sandbox() as box:
        box.install_checkout()
        inside = "/tmp/aarecovery-shot"
        work = box.host_path(inside)
        work.mkdir(parents=True, exist_ok=True)
        (work / "profile").mkdir(exist_ok=True)
        (work / "profile" / "gimprc").write_text("(show-welcome-dialog no)\n(show-tips no)\n")
        write_png(work / "scene.png", scene(160, 220, 4)[..., :3], 8)
        box.run([sandbox.VENV_PYTHON, "-m", "aarecovery.gimp", "install"],
                env={"GIMP3_DIRECTORY": f"{inside}/profile"})
        (work / "open.py").write_text(textwrap.dedent(f"""
            image = Gimp.file_load(Gimp.RunMode.NONINTERACTIVE, Gio.File.new_for_path('{inside}/scene.png'))
            Gimp.Display.new(image)
            proc = Gimp.get_pdb().lookup_procedure('plug-in-aarecovery-apply-filter')
            cfg = proc.create_config()
            cfg.set_property('run-mode', Gimp.RunMode.INTERACTIVE)
            cfg.set_property('image', image)
            cfg.set_core_object_array('drawables', image.get_layers())
            proc.run(cfg)
        """))
        script = f"""
            Xvfb :77 -screen 0 1400x1000x24 -nolisten tcp 2>/dev/null & XPID=$!
            sleep 2
            DISPLAY=:77 GIMP3_DIRECTORY={inside}/profile PYTHONPATH={sandbox.SITE} \\
              gimp-3.0 -n --no-splash --batch-interpreter=python-fu-eval \\
              -b "exec(open('{inside}/open.py').read())" >{inside}/gimp.log 2>&1 & GPID=$!
            for i in $(seq 1 60); do
              sleep 2
              xwd -display :77 -name '{TITLE}' -out {inside}/dialog.xwd 2>/dev/null && break
            done
            sleep 3
            xwd -display :77 -name '{TITLE}' -out {inside}/dialog.xwd
            kill $GPID; sleep 2; kill $XPID
        """
        proc = box.run(["sh", "-c", textwrap.dedent(script)], timeout=300, check=False)
        try:
            shot = work / "dialog.xwd"
            if not shot.exists():
                log = (work / "gimp.log").read_text(errors="replace")[-3000:]
                sys.exit(f"no dialog appeared:\n{proc.stderr}\n{log}")
            Path(out).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(xwd_to_array(shot.read_bytes())).save(out, optimize=True)
            print(f"wrote {out}")
        finally:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main(*sys.argv[1:])
