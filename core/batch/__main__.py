"""``python -m aarecovery.batch``: one of a batch's analysis processes (started by the batch itself).

It reads plan requests on its standard input and answers on its standard output until the
input ends; see :mod:`aarecovery.batch.planner`.
"""

from .planner import serve

serve()
