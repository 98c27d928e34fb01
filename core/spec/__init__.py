"""The NumPy specification of the recovery: every pass, executable.

Read :mod:`aarecovery.spec.passes` first: the passes in order, each with a GL twin of the
same name. The modules below it hold one idea each: the neighbourhood
(:mod:`~aarecovery.spec.neighbourhood`), the one Sobel (:mod:`~aarecovery.spec.sobel`), the
working space (:mod:`~aarecovery.spec.working_space`), the paper's model
(:mod:`~aarecovery.spec.blend_model`), the safe default's pure colours of thin features
(:mod:`~aarecovery.spec.pure_colours`) and the Jacobi step (:mod:`~aarecovery.spec.jacobi`).
"""

from .blend_model import BlendModel
from .passes import fit_blend_model, from_working_space, jacobi_step, recover_working, to_working_space
from .pure_colours import PureColourPrior

__all__ = ["BlendModel", "PureColourPrior", "to_working_space", "fit_blend_model", "jacobi_step",
           "from_working_space", "recover_working"]
