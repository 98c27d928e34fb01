"""The NumPy backend behind :class:`aarecovery.Engine`."""

import numpy as np

from ._contract import to_rgba_float
from ._reference import fit_blend_model, from_working_space, jacobi_step, to_working_space

__all__ = ["NumpyBackend"]


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
        model = fit_blend_model(self._original, self._filtered, params.sigma_d, params.sigma_e,
                                getattr(params, "strength", 1.0))
        recovered = self._filtered
        for _ in range(params.iterations):
            recovered = jacobi_step(recovered, self._filtered, model)
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
