"""The plan's analyses run beside its decisions in a second thread (plan/ahead.py): the same
plans as in order, for every decision of the safe default."""

import dataclasses
import subprocess
import sys
from contextlib import contextmanager

import numpy as np
import pytest

import aarecovery.plan.analysis as analysis
from aarecovery.params import Parameters
from aarecovery.plan import make_plan
from aarecovery.plan.ahead import InOrder, analyses_ahead
from test_decisions import PAIRS


def _assert_same(first, second, where="plan"):
    if dataclasses.is_dataclass(first) and not isinstance(first, type):
        assert type(first) is type(second), where
        for field in dataclasses.fields(first):
            _assert_same(getattr(first, field.name), getattr(second, field.name), f"{where}.{field.name}")
    elif isinstance(first, np.ndarray):
        np.testing.assert_array_equal(first, second, err_msg=where)
    elif isinstance(first, (tuple, list)):
        assert len(first) == len(second), where
        for index, (a, b) in enumerate(zip(first, second)):
            _assert_same(a, b, f"{where}[{index}]")
    else:
        assert first == second, where


@contextmanager
def _in_order():
    yield InOrder()


@pytest.mark.parametrize("decision", list(PAIRS), ids=str)
def test_the_plan_is_the_same_in_order(decision, monkeypatch):
    original, filtered = PAIRS[decision]()
    beside = make_plan(original, filtered, Parameters(), mode="safe")
    monkeypatch.setattr(analysis, "analyses_ahead", _in_order)
    in_order = make_plan(original, filtered, Parameters(), mode="safe")
    assert beside.decision == decision
    _assert_same(beside, in_order)


def test_a_thread_where_the_address_space_is_free_in_order_where_it_is_limited():
    with analyses_ahead() as ahead:
        assert not isinstance(ahead, InOrder)
        assert ahead.submit(sum, (1, 2)).result() == 3
    code = ("import resource\n"
            "resource.setrlimit(resource.RLIMIT_AS, (64 * 2**30, resource.RLIM_INFINITY))\n"
            "from aarecovery.plan.ahead import InOrder, analyses_ahead\n"
            "with analyses_ahead() as ahead:\n"
            "    print(type(ahead).__name__, ahead.submit(sum, (1, 2)).result())\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["InOrder", "3"]


def test_in_order_an_analysis_raises_where_its_result_is_read():
    done = InOrder().submit(int, "not a number")
    assert done.done()
    with pytest.raises(ValueError, match="not a number"):
        done.result()


def test_a_batchs_analysis_process_plans_in_order():
    # Its processes use every core already (aarecovery.batch.planner).
    code = ("import io\n"
            "from aarecovery.batch.planner import serve\n"
            "from aarecovery.plan.ahead import analyses_ahead\n"
            "serve(io.BytesIO(), io.BytesIO())\n"
            "with analyses_ahead() as ahead:\n"
            "    print(type(ahead).__name__)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["InOrder"]
