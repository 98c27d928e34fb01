"""The NumPy backend behind :class:`aarecovery.Engine`."""

import numpy as np

from ._contract import to_rgba_float
from ._reference import BlendModel, fit_blend_model, from_working_space, jacobi_step, to_working_space

__all__ = ["NumpyBackend"]

# The passes run on strips of rows: their ~40 temporary planes then stay in cache, which
# made them twice as fast at 1920x1080 (measured). A strip carries a halo of
# iterations + 1 rows (the dependency radius, as for tiles, see ``halo_for``), so the result
# is the same as over the whole image.
_STRIP_ROWS = 64
_MODEL_FIELDS = ("alpha", "beta", "index_a", "index_b", "residual", "edge")


def _recover_in_strips(original, filtered, params, blend_space):
    height = original.shape[0]
    halo = params.iterations + 1
    recovered = np.empty_like(filtered)
    columns = []
    for top in range(0, height, _STRIP_ROWS):
        bottom = min(height, top + _STRIP_ROWS)
        start, stop = max(0, top - halo), min(height, bottom + halo)
        strip_o, strip_f = original[start:stop], filtered[start:stop]
        model = fit_blend_model(strip_o, strip_f, params.sigma_d, params.sigma_e, params.strength,
                                params.pure_colours, blend_space)
        result = strip_f
        for _ in range(params.iterations):
            result = jacobi_step(result, strip_f, model)
        inner = slice(top - start, top - start + bottom - top)
        recovered[top:bottom] = result[inner]
        columns.append([getattr(model, name)[inner] for name in _MODEL_FIELDS])
    # The pure-colour fields only serve the Jacobi steps inside a strip; maps do not show them.
    return recovered, BlendModel(*(np.concatenate(parts) for parts in zip(*columns)))


class NumpyBackend:
    name = "numpy"

    def __init__(self):
        self._original = self._filtered = self._filtered_rgba = None
        self._result = self._model = None

    def load(self, original, o_layout, filtered, f_layout, linear_input, blend_space):
        self._space = dict(linear_input=linear_input, blend_space=blend_space)
        self._filtered_rgba = to_rgba_float(filtered, f_layout, "filtered")
        self._original = to_working_space(to_rgba_float(original, o_layout, "original"), **self._space)
        self._filtered = to_working_space(self._filtered_rgba, **self._space)
        self._result = self._model = None

    def run(self, params, maps):
        recovered, model = _recover_in_strips(self._original, self._filtered, params, self._space["blend_space"])
        self._result = from_working_space(recovered, self._filtered_rgba, filtered_work=self._filtered,
                                          **self._space)
        self._model = model

    def finish(self):
        pass

    def read_result(self):
        return self._result

    def read_maps(self):
        from ._engine import RecoveryMaps
        m = self._model
        return RecoveryMaps(m.alpha, m.beta, m.edge, m.residual)

    def release(self):
        self.__init__()
