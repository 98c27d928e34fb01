"""What ``aarecovery eval`` shows: the plain-text tables and the Markdown report with crops."""

import os

import numpy as np

from ..extras import install_command
from .evaluate import MAX_LOSS_DB, MIN_MEAN_REDUCTION, methods_of, summarize

__all__ = ["format_table", "write_report"]


def format_table(results, missing=(), suite=None):
    """Plain-text tables, one per filter, and the summary: what ``aarecovery eval`` prints.

    `suite` names the suite in the summary lines (``"the quick suite"``): its figures differ
    from another suite's, and a figure quoted without it cannot be compared.
    """
    methods = methods_of(results)
    lines = []
    for peer in missing:
        lines.append(f"!! {peer.label} is NOT installed (`{peer.command}` not found; Debian package "
                     f"'{peer.package}'): its column is missing from every table below")
    names = list(dict.fromkeys(r.filter_name for r in results))
    head = (f"{'scene':10s} {'aa':6s} | " + " ".join(f"{m:>6s}" for m in methods) + " | "
            + " ".join(f"{m:>6s}" for m in methods) + " | " + " ".join(f"{m:>6s}" for m in methods[1:])
            + " | " + f"{'psnr F':>6s} {'R':>6s} {'ssim F':>6s} {'R':>6s}")
    for name in names:
        lines.append("")
        lines.append(f"== {name}: edge-band PSNR (dB) | edge-band SSIM | edge-band error reduction | whole image")
        lines.append(head)
        for r in (r for r in results if r.filter_name == name):
            lines.append(f"{r.scene:10s} {r.space:6s} | "
                         + " ".join(f"{r.psnr_band[m]:6.2f}" for m in methods) + " | "
                         + " ".join(f"{r.ssim_band[m]:6.4f}"[:6] for m in methods) + " | "
                         + " ".join(f"{r.reduction[m]:+6.3f}"[:6] for m in methods[1:]) + " | "
                         + f"{r.psnr['F']:6.2f} {r.psnr['R']:6.2f} {r.ssim['F']:6.4f} {r.ssim['R']:6.4f}")
    summary = summarize(results)
    lines.append("")
    lines.append("== summary: mean edge-band PSNR gain over F (dB)")
    others = methods[1:]
    lines.append(f"{'filter':14s} " + " ".join(f"{m:>7s}" for m in others) + "  R beats peers")
    for name, gains in summary["per_filter"].items():
        verdict = "" if name == "blur" else ("yes" if summary["beats_peers"].get(name) else "NO")
        lines.append(f"{name:14s} " + " ".join(f"{gains[m]:+7.2f}" for m in others) + f"  {verdict}")
    loss, where = summary["worst_loss_db"]
    lines.append("")
    lines.append(f"worst edge-band loss of R against F: {loss:+.2f} dB ({where}); "
                 f"limit {MAX_LOSS_DB} dB: {'ok' if loss <= MAX_LOSS_DB else 'FAILED'}")
    for space, values in summary["mean_reduction"].items():
        verdict = "ok" if values["R"] >= MIN_MEAN_REDUCTION else "FAILED"
        paper = f" (paper {values['paper']:.3f})" if "paper" in values else ""
        lines.append(f"mean edge-band error reduction{f' on {suite}' if suite else ''}, synthetic, {space} "
                     "antialiasing, blur excluded: "
                     f"R {values['R']:.3f}{paper}; target {MIN_MEAN_REDUCTION}: {verdict}")
    return "\n".join(lines)


def _crop_box(result, size=32):
    """The size x size window where F is furthest from the reference."""
    error = np.abs(result.images["F"] - result.images["reference"]).max(axis=-1)
    h, w = error.shape
    size = min(size, h, w)
    integral = np.pad(error, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    sums = integral[size:, size:] - integral[:-size, size:] - integral[size:, :-size] + integral[:-size, :-size]
    top, left = np.unravel_index(np.argmax(sums), sums.shape)
    return int(top), int(left), size


def _magnified(image, zoom):
    return np.repeat(np.repeat(image, zoom, axis=0), zoom, axis=1)


def _crop_strip(result, methods, zoom=6):
    top, left, size = _crop_box(result)
    panels = [_magnified(result.images[m][top:top + size, left:left + size], zoom) for m in methods]
    gap = np.ones((size * zoom, 4, 3), np.float32)
    pieces = []
    for panel in panels:
        pieces += [panel, gap]
    return np.concatenate(pieces[:-1], axis=1)


def write_report(results, folder, missing=(), command="aarecovery eval", suite=None):
    """Write ``report.md`` with tables, bar charts (matplotlib, optional) and magnified crops.

    Parameters
    ----------
    results : list of CaseResult
        From :func:`run_suite` with ``keep_images=True``.
    folder : str
        Created if missing.
    missing : list of Peer
    command : str
        The command line, quoted in the report.
    suite : str, optional
        The suite's name for the summary lines (:func:`format_table`).

    Returns
    -------
    str
        Path of the Markdown file.
    """
    from PIL import Image
    os.makedirs(folder, exist_ok=True)
    methods = methods_of(results)
    lines = ["# aarecovery evaluation", "", f"Command: `{command}`", ""]
    for peer in missing:
        lines.append(f"> **{peer.label} is not installed** (`{peer.command}`; Debian package `{peer.package}`): "
                     "it is missing from every table and chart.")
    lines += ["", "Columns: F (the filtered image), R (the safe default), paper (Yang et al. 2011 exactly)"
              + "".join(f", {m}" for m in methods if m in ("gimp", "gmic")) + ". All numbers are against the "
              "supersampled reference; the band is the edge band.", "", "```", format_table(results, missing, suite), "```",
              ""]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        plt = None
        lines += [f"> Bar charts need matplotlib (`{install_command('eval')}`); they were skipped.", ""]
    for name in dict.fromkeys(r.filter_name for r in results):
        picked = [r for r in results if r.filter_name == name]
        lines += [f"## {name}", ""]
        if plt is not None:
            figure, axes = plt.subplots(figsize=(max(4, 0.9 * len(picked) + 1), 2.8))
            width = 0.8 / len(methods)
            x = np.arange(len(picked))
            for i, method in enumerate(methods):
                axes.bar(x + i * width, [r.psnr_band[method] for r in picked], width, label=method)
            axes.set_xticks(x + 0.4 - width / 2, [f"{r.scene}\n{r.space}" for r in picked], fontsize=7)
            axes.set_ylabel("edge-band PSNR (dB)")
            low = min(min(r.psnr_band.values()) for r in picked)
            axes.set_ylim(max(0, low - 3), None)
            axes.legend(fontsize=7, ncol=len(methods))
            figure.tight_layout()
            chart = f"{name}-psnr.png"
            figure.savefig(os.path.join(folder, chart), dpi=90)
            plt.close(figure)
            lines += [f"![edge-band PSNR, {name}]({chart})", ""]
        worst = max(picked, key=lambda r: r.psnr_band["R"] - r.psnr_band["F"])
        shown = ["O", "F", "R", "reference"] + [m for m in ("paper", "gimp", "gmic") if m in worst.images]
        crop = f"{name}-crop.png"
        strip = _crop_strip(worst, shown)
        Image.fromarray(np.rint(np.clip(strip, 0, 1) * 255).astype(np.uint8)).save(os.path.join(folder, crop))
        lines += [f"Crop of {worst.scene} ({worst.space}), magnified 6x with nearest neighbour, left to right: "
                  + ", ".join(shown) + f". Safe default: {worst.plan}.", "", f"![{name} crop]({crop})", ""]
    path = os.path.join(folder, "report.md")
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("\n".join(lines))
    return path
