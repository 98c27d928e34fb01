"""Reading the block lists a GL backend made on the GPU, for the tests."""

import struct

import numpy as np

from aarecovery.backends.gl.blocks import DISPATCH_COMMAND_WORDS, DRAW_COMMAND_WORDS, LISTS, expand_runs


def gpu_lists(impl, image_name, raw=False):
    """``{list name: (N, 2) int32 (column, row)}`` of the uploaded O or F (`image_name`): the
    blocks, or with `raw` the entries as the GPU holds them (runs on the fragment path);
    call with the backend's context current."""
    lists = impl._block_lists(image_name)
    words = struct.unpack(f"{len(LISTS) * (DRAW_COMMAND_WORDS + DISPATCH_COMMAND_WORDS + 1)}I", lists.commands.read())
    lengths = {name: words[DRAW_COMMAND_WORDS * index + 1] for index, name in enumerate(LISTS)}
    if lists.counts is not None:
        assert lists.counts == lengths
    entries = {name: np.frombuffer(lists.buffers[name].read(), np.int32)[:2 * lengths[name]].reshape(-1, 2)
               for name in LISTS}
    blocks = {name: expand_runs(listed) for name, listed in entries.items()} if impl._classifier.runs else entries
    # The block counts that follow the commands (block_lists.glsl).
    assert words[-len(LISTS):] == tuple(len(blocks[name]) for name in LISTS)
    return entries if raw else blocks


def dispatch_sizes(impl, image_name):
    """``{list name: (x, y, z)}``: the indirect dispatch commands of the lists."""
    lists = impl._block_lists(image_name)
    words = struct.unpack(f"{len(LISTS) * (DRAW_COMMAND_WORDS + DISPATCH_COMMAND_WORDS + 1)}I", lists.commands.read())
    start = DRAW_COMMAND_WORDS * len(LISTS)
    return {name: words[start + DISPATCH_COMMAND_WORDS * index:start + DISPATCH_COMMAND_WORDS * (index + 1)]
            for index, name in enumerate(LISTS)}
