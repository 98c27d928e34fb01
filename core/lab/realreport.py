"""What ``aarecovery eval --suite realtools`` shows: per-case lines, summaries and the issue's targets."""

import os

import numpy as np

from .metrics import HAZE_TOLERANCE
from .realeval import (JPEG_TARGET_QUALITY, MAX_LOSS_DB, METHODS, MIN_HARD_REDUCTION, MIN_JPEG_GAIN_KEPT,
                       MIN_MIXED_REDUCTION, MIN_NEIGHBOURHOOD_REDUCTION, MIN_PHOTO_POINTWISE_REDUCTION,
                       MIN_TEXT_REDUCTION, REGIONS, mean_reductions, summarize_mixed, summarize_realtools)
from .report import TABLES_FILE, generated_block, markdown_table

__all__ = ["format_realtools", "realtools_markdown_tables", "write_realtools_report", "WORST_SHOWN"]

#: How many of the safe default's worst cases the summary lists.
WORST_SHOWN = 15
_HALF_NAMES = {"tune": "tuning", "heldout": "held-out", "all": "every"}
_HELD_OUT_WARNING = ("!! HELD-OUT HALF: report these numbers; choose no threshold, constant or rule by them "
                     "(tune on --half tune)")


def _reduction(value):
    """An error reduction in 7 characters: they range from 1 down to -10000 where F was nearly right."""
    if not np.isfinite(value):
        return f"{'n/a':>7s}"
    if abs(value) < 10:
        return f"{value:+7.3f}"
    return f"{value:+7.1f}" if abs(value) < 1000 else f"{value:+7.0e}"


def _present(results):
    present = set().union(*(r.psnr_band for r in results)) if results else set()
    return [m for m in METHODS if m in present]


def _case_lines(results, methods):
    reduced = methods[1:]
    head = (f"{'case':44s} " + " ".join(f"{m:>6s}" for m in methods) + " | "
            + " ".join(f"{m:>7s}" for m in reduced) + " |   chg%  max|R-F|   out | safe default's plan")
    lines = [head]
    for r in results:
        lines.append(f"{r.name:44s} " + " ".join(f"{r.psnr_band[m]:6.2f}" for m in methods) + " | "
                     + " ".join(_reduction(r.reduction[m]) for m in reduced) + " | "
                     + f"{100 * r.changed:6.2f} {r.max_change:8.3f} {r.outside.get('R', 0):5d} | {r.plan}")
    return lines


def _group_lines(results, key, title, methods, png_only=True):
    reduced = methods[1:]
    which = "PNG cases" if png_only else "cases"
    lines = ["", f"== per {title}: mean edge-band error reduction over {which} where F has an error (n) | "
                 f"R worse than F by > {MAX_LOSS_DB} dB, worst loss (every case)",
             f"{title:26s} {'n':>4s} " + " ".join(f"{m:>7s}" for m in reduced) + " | losses  worst dB"]
    names = dict.fromkeys(key(r) for r in results)
    if not png_only:  # sources: PNG, then JPEG by quality
        names = sorted(names, key=lambda name: (name != "png", name))
    for name in names:
        mine = [r for r in results if key(r) == name]
        means, count = mean_reductions([r for r in mine if r.quality is None or not png_only])
        losses = [r.psnr_band["F"] - r.psnr_band["R"] for r in mine]
        lines.append(f"{name:26s} {count:4d} " + " ".join(_reduction(means.get(m, np.nan)) for m in reduced)
                     + f" | {sum(1 for x in losses if x > MAX_LOSS_DB):6d} {max(losses):+9.2f}")
    return lines


def _verdict(ok):
    return "ok" if ok else "NOT MET"


def _target_lines(results, summary):
    methods = [m for m in METHODS[1:] if m in summary["hard"]]

    def others(values, skip="R"):
        return ", ".join(f"{m} {_reduction(values[m]).strip()}" for m in methods if m != skip and m in values)

    loss, where = summary["worst_loss_db"]
    lines = ["", "== targets of issue 10 (asserted on the held-out half once met)",
             f"never worse than F by more than {MAX_LOSS_DB} dB (edge band, every case: photos, JPEG, every tool): "
             f"worst loss {loss:+.2f} dB ({where}); {summary['losses_over_limit']} of {len(results)} cases over: "
             f"{_verdict(summary['losses_over_limit'] == 0)}"]
    hard = summary["hard"]
    lines.append(f"hard-edged drawings, PNG originals, mean edge-band error reduction ({summary['hard_cases']} "
                 f"cases): R {_reduction(hard.get('R', np.nan)).strip()} ({others(hard)}); target "
                 f"{MIN_HARD_REDUCTION}: {_verdict(hard.get('R', -np.inf) >= MIN_HARD_REDUCTION)}")
    behind = summary["behind_peers"]
    lines.append(f"R ahead of GIMP's, G'MIC's antialias and the joint bilateral filter on every filter (drawings, "
                 f"PNG): {_verdict(not behind)}" + (f"; behind on {', '.join(behind)}" if behind else ""))
    label = f"q>={JPEG_TARGET_QUALITY}"
    if label in summary["jpeg_gain_kept"]:
        kept = summary["jpeg_gain_kept"][label]
        value, pairs = kept.get("R", (np.nan, 0))
        per_quality = "; ".join(f"{q[1:]}: {v['R'][0]:.2f} ({v['R'][1]})"
                                for q, v in summary["jpeg_gain_kept"].items() if q != label and "R" in v)
        lines.append(f"JPEG originals ({label}) keep of R's gain on the same pairs with PNG originals: {value:.2f} "
                     f"({pairs} pairs where R gains on PNG; paper {kept.get('paper', (np.nan, 0))[0]:.2f}); target "
                     f"{MIN_JPEG_GAIN_KEPT}: {_verdict(value >= MIN_JPEG_GAIN_KEPT)}; "
                     f"per quality (pairs): {per_quality}")
    photo = summary["photo_pointwise"]
    lines.append(f"photos under point-wise filters (threshold, levels, curves, posterize), PNG originals, mean "
                 f"reduction ({summary['photo_pointwise_cases']} cases): "
                 f"R {_reduction(photo.get('R', np.nan)).strip()} "
                 f"({others(photo)}); target {MIN_PHOTO_POINTWISE_REDUCTION}: "
                 f"{_verdict(photo.get('R', -np.inf) >= MIN_PHOTO_POINTWISE_REDUCTION)}")
    outside = summary["outside"]
    pixels, cases = outside.get("R", (0, 0))
    context = ", ".join(f"{m} {outside[m][0]} in {outside[m][1]}" for m in outside if m != "R")
    lines.append(f"R pixels outside F's local colour range (3x3 min/max per channel, 1/255 slack): {pixels} in "
                 f"{cases} cases ({context}); target 0: {_verdict(pixels == 0)}")
    return lines


def _target_rows(results, summary):
    """(target, R, the others, limit, met) for each of the issue's targets."""
    methods = [m for m in METHODS[1:] if m in summary["hard"]]

    def others(values):
        return ", ".join(f"{m} {_reduction(values[m]).strip()}" for m in methods if m != "R" and m in values)

    def met(ok):
        return "yes" if ok else "**no**"

    loss, where = summary["worst_loss_db"]
    over = summary["losses_over_limit"]
    rows = [(f"1. never worse than F by more than {MAX_LOSS_DB} dB", f"worst loss {loss:+.2f} dB ({where}); {over} of "
             f"{len(results)} cases over", "", "0 cases", met(over == 0))]
    hard = summary["hard"]
    rows.append((f"2. drawings, PNG originals: mean error reduction ({summary['hard_cases']} cases)",
                 _reduction(hard.get("R", np.nan)).strip(), others(hard), f"{MIN_HARD_REDUCTION}",
                 met(hard.get("R", -np.inf) >= MIN_HARD_REDUCTION)))
    behind = summary["behind_peers"]
    rows.append(("2. R ahead of every peer on every filter (drawings, PNG)",
                 "every filter" if not behind else "behind on " + ", ".join(behind), "", "every filter",
                 met(not behind)))
    label = f"q>={JPEG_TARGET_QUALITY}"
    if label in summary["jpeg_gain_kept"]:
        kept = summary["jpeg_gain_kept"][label]
        value, pairs = kept.get("R", (np.nan, 0))
        rows.append((f"3. JPEG originals ({label}): share of R's PNG gain kept ({pairs} pairs)", f"{value:.2f}",
                     f"paper {kept.get('paper', (np.nan, 0))[0]:.2f}", f"{MIN_JPEG_GAIN_KEPT}",
                     met(value >= MIN_JPEG_GAIN_KEPT)))
    photo = summary["photo_pointwise"]
    rows.append((f"4. photos under point-wise filters, PNG: mean error reduction "
                 f"({summary['photo_pointwise_cases']} cases)", _reduction(photo.get("R", np.nan)).strip(),
                 others(photo), f"{MIN_PHOTO_POINTWISE_REDUCTION}",
                 met(photo.get("R", -np.inf) >= MIN_PHOTO_POINTWISE_REDUCTION)))
    outside = summary["outside"]
    pixels, cases = outside.get("R", (0, 0))
    rows.append(("5. R pixels outside F's 3 x 3 colour range", f"{pixels} in {cases} cases",
                 ", ".join(f"{m} {outside[m][0]}" for m in outside if m != "R"), "0", met(pixels == 0)))
    return rows + _region_rows(summary, others, met)


# The methods besides R that the haze row names (the peers run on F alone: GIMP's and G'MIC's
# antialias, the joint bilateral filter).
_HAZE_OTHERS = ("paper", "gimp", "gmic", "jbf")


def _region_rows(summary, others, met):
    """The local plan's targets: mixed content per region, neighbourhood filters, haze."""
    rows = []
    for key, which in (("mixed", "every filter"), ("mixed_pointwise", "point-wise filters")):
        mixed = summary.get(key)
        if not mixed or not any(mixed[region][1] for region in REGIONS):
            continue
        text, photo = (mixed[region] for region in REGIONS)
        rows.append((f"6. mixed content under {which}: text and graphics regions ({text[1]} cases)",
                     _reduction(text[0].get("R", np.nan)).strip(), others(text[0]), f"{MIN_TEXT_REDUCTION}",
                     met(text[0].get("R", -np.inf) >= MIN_TEXT_REDUCTION)))
        rows.append((f"6. mixed content under {which}: photo regions worse than F ({photo[1]} cases)",
                     f"{len(photo[2])} (mean {_reduction(photo[0].get('R', np.nan)).strip()}"
                     + (f"; worst {photo[3]:.2f} dB)" if photo[2] else ")"), others(photo[0]),
                     "0", met(not photo[2])))
        overall, cases = mixed["overall"]
        rows.append((f"6. mixed content under {which}: whole edge band ({cases} cases)",
                     _reduction(overall.get("R", np.nan)).strip(), others(overall), f"{MIN_MIXED_REDUCTION}",
                     met(overall.get("R", -np.inf) >= MIN_MIXED_REDUCTION)))
    if summary.get("neighbourhood_cases"):
        near = summary["neighbourhood"]
        loss, where = summary["neighbourhood_worst_db"]
        rows.append((f"7. neighbourhood filters on drawings, PNG ({summary['neighbourhood_cases']} cases)",
                     f"{_reduction(near.get('R', np.nan)).strip()}; worst loss {loss:+.2f} dB ({where})", others(near),
                     f"{MIN_NEIGHBOURHOOD_REDUCTION}, no loss",
                     met(near.get("R", -np.inf) >= MIN_NEIGHBOURHOOD_REDUCTION and loss <= 0)))
    haze = summary.get("haze", {}).get("jpeg")
    if haze and "R" in haze:
        pixels, hazed, cases = haze["R"]
        darker = haze["darker"]
        rows.append((f"8. JPEG scans: pixels of F's flat paper that R makes darker than F ({cases} cases)",
                     f"{pixels} in {hazed} cases",
                     ", ".join(f"{m} {haze[m][0]}" for m in _HAZE_OTHERS if m in haze)
                     + "; anywhere on the paper: " + ", ".join(f"{m} {darker[m][0]}" for m in ("R", *_HAZE_OTHERS,
                                                                                              "reference") if m in darker),
                     "0", met(pixels == 0)))
    return rows


def realtools_markdown_tables(results, missing_tools=(), missing_peers=(), *, suite_name="realtools", half="tune",
                              command="aarecovery eval --suite realtools"):
    """The Markdown tables that docs/quality.md includes for one half: the issue's targets and
    the mean error reduction per group of filters, in a block marked with its command."""
    methods = _present(results)
    reduced = methods[1:]
    png = sum(1 for r in results if r.quality is None)
    lines = [f"Real-tools suite {suite_name!r}, {_HALF_NAMES.get(half, half)} half: {len(results)} "
             f"cases ({png} PNG, {len(results) - png} JPEG)"
             + "".join(f"; **{item.label} was not installed**" for item in (*missing_tools, *missing_peers))
             + ".", ""]
    summary = summarize_realtools(results)
    lines += markdown_table(("target", "R", "others", "limit", "met"), _target_rows(results, summary)) + [""]
    lines += [f"Mean edge-band error reduction per group of filters (PNG cases where F has an error), the cases "
              f"where R loses more than {MAX_LOSS_DB} dB against F, and R's worst loss (every case; below 0, the "
              "least gain):", ""]
    rows = []
    for group in dict.fromkeys(r.group for r in results):
        mine = [r for r in results if r.group == group]
        means, count = mean_reductions([r for r in mine if r.quality is None])
        losses = [r.psnr_band["F"] - r.psnr_band["R"] for r in mine]
        rows.append((group, count) + tuple(_reduction(means.get(m, np.nan)).strip() for m in reduced)
                    + (sum(1 for x in losses if x > MAX_LOSS_DB), f"{max(losses):+.2f}"))
    lines += markdown_table(("group", "n") + tuple(reduced) + ("losses", "worst loss dB"), rows)
    return generated_block(command, "\n".join(lines))


def _means(values, skip=()):
    return ", ".join(f"{m} {_reduction(v).strip()}" for m, v in values.items() if m not in skip)


def _mixed_target_lines(mixed, which):
    text, photo = (mixed[region] for region in REGIONS)
    if not (text[1] or photo[1]):
        return []
    overall, cases = mixed["overall"]
    return [f"mixed content under {which}, text/graphics regions' edge band, PNG originals ({text[1]} cases): "
            f"R {_reduction(text[0].get('R', np.nan)).strip()} ({_means(text[0], ('R',))}); target "
            f"{MIN_TEXT_REDUCTION}: {_verdict(text[0].get('R', -np.inf) >= MIN_TEXT_REDUCTION)}; "
            f"{len(text[2])} cases worse than F",
            f"mixed content under {which}, photo regions' edge band ({photo[1]} cases): R "
            f"{_reduction(photo[0].get('R', np.nan)).strip()} ({_means(photo[0], ('R',))}); target: at least "
            f"the calibrated strength of today's plan, no region worse than F: {len(photo[2])} cases worse"
            + (f", the worst by {photo[3]:.2f} dB ({', '.join(photo[2][:4])})" if photo[2] else ""),
            f"mixed content under {which}, whole edge band ({cases} cases): R "
            f"{_reduction(overall.get('R', np.nan)).strip()} ({_means(overall, ('R',))}); target "
            f"{MIN_MIXED_REDUCTION}: {_verdict(overall.get('R', -np.inf) >= MIN_MIXED_REDUCTION)}"]


def _haze_lines(results):
    scans = [r for r in results if r.kind == "scan"]
    if not scans:
        return []
    lines = ["", f"== scans: haze per filter, pixels of F's flat paper made darker than F by more than "
                 f"{HAZE_TOLERANCE * 255:g}/255 in luma (cases with any / cases); anywhere on the paper, R's and "
                 "the reference's own",
             f"{'filter':26s} {'R png':>14s} {'paper png':>14s} {'R jpeg':>14s} {'paper jpeg':>14s}"
             f" {'R anywhere':>11s} {'reference':>10s}"]
    for name in dict.fromkeys(r.filter_name for r in scans):
        cells = []
        for png in (True, False):
            mine = [r for r in scans if r.filter_name == name and (r.quality is None) == png]
            for method in ("R", "paper"):
                pixels = sum(r.haze.get(method, 0) for r in mine)
                cells.append(f"{pixels:7d} {sum(1 for r in mine if r.haze.get(method)):2d}/{len(mine):<2d}")
        mine = [r for r in scans if r.filter_name == name]
        anywhere = [sum(r.darker.get(m, 0) for r in mine) for m in ("R", "reference")]
        lines.append(f"{name:26s} {cells[0]:>14s} {cells[1]:>14s} {cells[2]:>14s} {cells[3]:>14s}"
                     f" {anywhere[0]:11d} {anywhere[1]:10d}")
    return lines


def _issue19_lines(results, summary):
    lines = ["", "== targets of issue 19 (asserted on the held-out half once met)"]
    for key, which in (("mixed", "every filter"), ("mixed_pointwise", "point-wise filters")):
        lines += _mixed_target_lines(summary[key], which)
    if summary["neighbourhood_cases"]:
        near = summary["neighbourhood"]
        loss, where = summary["neighbourhood_worst_db"]
        lines.append(f"neighbourhood filters (unsharp, bilateral, abstraction, detail) on hard-edged drawings, PNG "
                     f"originals ({summary['neighbourhood_cases']} cases): R {_reduction(near.get('R', np.nan)).strip()}"
                     f" ({_means(near, ('R',))}); target {MIN_NEIGHBOURHOOD_REDUCTION}: "
                     f"{_verdict(near.get('R', -np.inf) >= MIN_NEIGHBOURHOOD_REDUCTION)}; worst loss to F "
                     f"{loss:+.2f} dB ({where})")
    haze = summary["haze"]
    if haze:
        parts = []
        for label, values in haze.items():
            counts = ", ".join(f"{m} {values[m][0]} px in {values[m][1]}" for m in ("R", "paper", "jbf") if m in values)
            darker = values["darker"]
            parts.append(f"{label} ({values['R'][2]} cases, {values['flat_paper_pixels']} of {values['paper_pixels']} "
                         f"paper px flat in F): {counts} (anywhere on the paper: R {darker['R'][0]}, reference "
                         f"{darker['reference'][0]})")
        lines.append(f"scans: haze, pixels of F's flat paper made darker than F by more than "
                     f"{HAZE_TOLERANCE * 255:g}/255 in luma; target 0 (F has none by definition): " + "; ".join(parts))
    return lines


def _mixed_lines(results):
    mixed = [r for r in results if r.kind == "mixed" and r.quality is None]
    if not mixed:
        return []
    lines = ["", "== mixed content per family: mean edge-band error reduction per region, PNG cases where F has an "
                 "error there (n)",
             f"{'family':14s} " + " ".join(f"{region + ' R':>17s} {'paper':>7s} {'n':>3s}" for region in REGIONS)
             + f" {'overall R':>10s} {'paper':>7s}"]
    for family in dict.fromkeys(r.scene for r in mixed):
        summary = summarize_mixed([r for r in mixed if r.scene == family])
        cells = []
        for region in REGIONS:
            means, count = summary[region][:2]
            cells.append(f"{_reduction(means.get('R', np.nan)):>17s} {_reduction(means.get('paper', np.nan))} "
                         f"{count:3d}")
        overall = summary["overall"][0]
        lines.append(f"{family:14s} " + " ".join(cells) + f" {_reduction(overall.get('R', np.nan)):>10s} "
                     f"{_reduction(overall.get('paper', np.nan))}")
    return lines


def format_realtools(results, missing_tools=(), missing_peers=(), *, suite_name="realtools", half="tune"):
    """Plain-text report of a real-tools run: what ``aarecovery eval --suite realtools`` prints."""
    methods = _present(results)
    png = sum(1 for r in results if r.quality is None)
    lines = [f"real-tools suite {suite_name!r}, half {half!r}: {len(results)} cases ({png} PNG, "
             f"{len(results) - png} JPEG), {len({r.scene for r in results})} scene families, "
             f"{len({r.filter_name for r in results})} tool filters"]
    if half != "tune":
        lines.append(_HELD_OUT_WARNING)
    for tool in missing_tools:
        lines.append(f"!! {tool.label} is NOT installed ({tool.install_hint()}): its cases are missing")
    for peer in missing_peers:
        lines.append(f"!! {peer.label} is NOT installed (`{peer.command}` not found; Debian package "
                     f"'{peer.package}'): its column is missing")
    lines += ["", "== cases: edge-band PSNR (dB) | edge-band error reduction | share of pixels R changed, largest "
                  "change, R pixels outside F's local range | the safe default's plan"]
    lines += _case_lines(results, methods)
    lines += _group_lines(results, lambda r: r.tool, "tool", methods)
    lines += _group_lines(results, lambda r: r.filter_name, "filter", methods)
    lines += _group_lines(results, lambda r: r.group, "group", methods)
    lines += _group_lines(results, lambda r: r.scene, "family", methods)
    lines += _group_lines(results, lambda r: r.source, "source", methods, png_only=False)
    lines += _mixed_lines(results)
    lines += _haze_lines(results)
    summary = summarize_realtools(results)
    lines += _target_lines(results, summary)
    lines += _issue19_lines(results, summary)
    worst = sorted(results, key=lambda r: r.psnr_band["R"] - r.psnr_band["F"])[:WORST_SHOWN]
    lines += ["", f"== the {len(worst)} worst cases of the safe default (edge-band PSNR of R minus F)",
              f"{'case':44s} {'F':>6s} {'R':>6s} {'R-F dB':>7s} {'red R':>7s} {'chg%':>6s} {'max':>6s} "
              f"{'out':>5s} | plan"]
    for r in worst:
        lines.append(f"{r.name:44s} {r.psnr_band['F']:6.2f} {r.psnr_band['R']:6.2f} "
                     f"{r.psnr_band['R'] - r.psnr_band['F']:+7.2f} {_reduction(r.reduction['R'])} "
                     f"{100 * r.changed:6.2f} {r.max_change:6.3f} {r.outside.get('R', 0):5d} | {r.plan}")
    return "\n".join(lines)


def write_realtools_report(results, folder, missing_tools=(), missing_peers=(), *, suite_name="realtools",
                           half="tune", command="aarecovery eval --suite realtools"):
    """Write ``report.md``, the text report and magnified crops of the safe default's worst cases,
    and ``tables.md``, the Markdown tables that docs/quality.md includes
    (:func:`realtools_markdown_tables`).

    Parameters
    ----------
    results : list of RealCaseResult
        From :func:`~aarecovery.lab.realeval.run_realtools` with ``keep_images=True``.
    folder : str
        Created if missing.

    Returns
    -------
    str
        Path of the Markdown file.
    """
    from PIL import Image

    from .report import _crop_strip
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, TABLES_FILE), "w", encoding="utf-8") as handle:
        handle.write(realtools_markdown_tables(results, missing_tools, missing_peers, suite_name=suite_name,
                                               half=half, command=command))
    lines = ["# aarecovery evaluation: real tools", "", f"Command: `{command}`", "", "```",
             format_realtools(results, missing_tools, missing_peers, suite_name=suite_name, half=half), "```", ""]
    worst = sorted(results, key=lambda r: r.psnr_band["R"] - r.psnr_band["F"])[:8]
    for i, result in enumerate(worst):
        shown = ["O", "F", "R", "reference"] + [m for m in ("paper", "gimp", "gmic", "jbf") if m in result.images]
        crop = f"worst-{i + 1}.png"
        strip = _crop_strip(result, shown)
        Image.fromarray(np.rint(np.clip(strip, 0, 1) * 255).astype(np.uint8)).save(os.path.join(folder, crop))
        lines += [f"## {result.name}: R {result.psnr_band['R'] - result.psnr_band['F']:+.2f} dB against F", "",
                  "Magnified 6x, left to right: " + ", ".join(shown) + f". Safe default: {result.plan}.", "",
                  f"![{result.name}]({crop})", ""]
    path = os.path.join(folder, "report.md")
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("\n".join(lines))
    return path
