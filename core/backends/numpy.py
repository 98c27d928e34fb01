"""The NumPy backend: the specification's passes (``aarecovery.spec``) on row strips."""

import numpy as np

from ..contract import to_rgba_float
from ..spec import BlendModel, from_working_space, recover_working, to_working_space
from ..spec.blend_model import toward_weight
from ..spec.local_plan import LocalStrength, encoded_colour, strength_map
from ..spec.ramp_lookup import ramp_lookup
from ..tiling import DEFAULT_TILES, halo_for
from .base import Capabilities, ReadyResult, RecoveryMaps

__all__ = ["NumpyBackend"]
# The passes run on strips of rows: their ~40 temporary planes then stay in cache, which
# made them twice as fast at 1920x1080 (measured). A strip carries the halo of a tile
# (``halo_for``), so the result is the same as over the whole image; with iterations + 1
# rows, maps alone (no iteration) with pure colours differed on the rows beside each seam.
_STRIP_ROWS = 64


def _recover_in_strips(original, filtered, plan, factor, gate, toward=None):
    height = original.shape[0]
    halo = halo_for(plan.iterations)
    recovered = np.empty_like(filtered)
    columns = []
    for top in range(0, height, _STRIP_ROWS):
        bottom = min(height, top + _STRIP_ROWS)
        start, stop = max(0, top - halo), min(height, bottom + halo)
        result, model = recover_working(original[start:stop], filtered[start:stop], plan.sigma_d, plan.sigma_e,
                                        plan.iterations, plan.strength, plan.pure_colours, plan.blend_space,
                                        None if factor is None else factor[start:stop], plan.untouched_span,
                                        None if gate is None else gate[start:stop],
                                        toward=None if toward is None else toward[start:stop],
                                        best_pair=plan.best_pair)
        inner = slice(top - start, top - start + bottom - top)
        recovered[top:bottom] = result[inner]
        columns.append([getattr(model, name)[inner] for name in BlendModel.MAP_FIELDS])
    # The pure-colour fields only serve the Jacobi steps inside a strip; maps do not show them.
    return recovered, BlendModel(*(np.concatenate(parts) for parts in zip(*columns)))


class NumpyBackend:
    """The passes in NumPy, on the CPU; the reference the GL backend is tested against."""

    name = "numpy"
    capabilities = Capabilities(max_tile=DEFAULT_TILES["numpy"], default_tile=DEFAULT_TILES["numpy"])

    def __init__(self):
        self._original = self._filtered = self._filtered_rgba = None
        self._result = self._model = self._strength = None
        self._encoded = self._original_rgba = None

    def load(self, original, o_layout, filtered, f_layout, linear_input, blend_space):
        self._space = dict(linear_input=linear_input, blend_space=blend_space)
        self._filtered_rgba = to_rgba_float(filtered, f_layout, "filtered")
        original_rgba = to_rgba_float(original, o_layout, "original")
        self._original_rgba = original_rgba
        self._encoded = encoded_colour(original_rgba, linear_input)
        self._original = to_working_space(original_rgba, **self._space)
        self._filtered = to_working_space(self._filtered_rgba, **self._space)
        self._result = self._model = self._strength = None

    def run(self, plan, maps):
        factor = None if plan.local is None else plan.local.factor(self._encoded)
        # Pure colours that act on drawn content only are gated by the regions' weight (and
        # the drawn ink, with an ink gate).
        gate = None
        prior = plan.pure_colours
        if factor is not None and prior is not None and prior.drawn_only:
            gate = plan.local.gate(self._encoded, prior.ink_gate, prior.ink_span)
        # A smoothing filter's drawn edges move towards O by the gate of drawn content around
        # them: the pure colours' gate where they have one, else the regions' weight or the
        # drawn ink (read even without a local plan).
        # Where that gate leaves the drawn ink out (text over a photo), the ink moves too where
        # F kept its contrast (LocalStrength.kept_ink).
        toward = None
        if plan.toward_original:
            weight = gate if gate is not None else LocalStrength.gate(self._encoded, True)
            if gate is not None and not prior.ink_gate:
                filtered_encoded = encoded_colour(self._filtered_rgba, self._space["linear_input"])
                weight = np.maximum(weight, LocalStrength.kept_ink(self._encoded, filtered_encoded))
            toward = toward_weight(weight)
        recovered, model = _recover_in_strips(self._original, self._filtered, plan, factor, gate, toward)
        self._result = from_working_space(recovered, self._filtered_rgba, filtered_work=self._filtered,
                                          **self._space)
        if plan.ramp_table is not None and plan.iterations > 0:
            self._result = ramp_lookup(self._result, self._original_rgba, self._filtered_rgba, model.beta,
                                       plan.ramp_table)
        self._model = model
        self._strength = strength_map(plan, factor, self._original.shape[:2]) if maps else None

    def finish(self):
        pass

    def start_readback(self, window=None):
        return ReadyResult(self._result if window is None else self._result[window])

    def read_maps(self):
        m = self._model
        return RecoveryMaps(m.alpha, m.beta, m.edge, m.residual, self._strength)

    def release(self):
        self.__init__()
