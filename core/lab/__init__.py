"""The lab: how recovery is measured, never imported by the product.

Scenes rendered at several times the target resolution (:mod:`~aarecovery.lab.scenes`),
supersampled ground truth (:mod:`~aarecovery.lab.groundtruth`), quality measures
(:mod:`~aarecovery.lab.metrics`), the peer tools users would reach for instead
(:mod:`~aarecovery.lab.peers`), the evaluation (:mod:`~aarecovery.lab.evaluate`,
:mod:`~aarecovery.lab.report`), the demo (:mod:`~aarecovery.lab.demo`) and the benchmarks
(:mod:`~aarecovery.lab.bench`). A second suite runs the real tools (GEGL, G'MIC,
ImageMagick: :mod:`~aarecovery.lab.tools`) on drawings (:mod:`~aarecovery.lab.drawings`)
and photos, split into a tuning and a held-out half (:mod:`~aarecovery.lab.realtools`,
:mod:`~aarecovery.lab.realeval`, :mod:`~aarecovery.lab.realreport`). Only the command
line (``aarecovery.cli``) and the tests import it; an import-linter contract in
``pyproject.toml`` keeps it so.
"""
