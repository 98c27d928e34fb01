"""The block classification on the GPU: which blocks the passes cover, decided where the image is.

With compute shaders (GL 4.3) three dispatches and no readback: ``classify_blocks.comp``
flags the blocks, ``compact_blocks.comp`` appends each to its lists (``blocks.LISTS``) and
counts them into indirect draw and dispatch commands, ``finish_block_lists.comp`` turns the
counts into dispatch sizes. The passes then draw or dispatch with those commands, so the CPU
neither computes nor waits for the lists. Without compute shaders (GL 3.3 to 4.2) a fragment
pass makes the block mask, 1/256 of the image, which is read back and listed by NumPy.

Before this, NumPy classified F on the CPU before every upload: 0.30 s of a 4.2 s
``aarecovery recover`` on a 4096 x 4096 pair (9 tiles), with the pair's transfer waiting
for it.
"""

import struct

import moderngl
import numpy as np

from .blocks import BLOCK_SIDE, DISPATCH_COMMAND_WORDS, DRAW_COMMAND_WORDS, FIT_PLAIN, FIT_WHOLE, LISTS, block_lists
from .glsl import load_source

__all__ = ["BlockClassifier", "BlockLists", "MAX_GROUPS", "block_grid"]

_DRAW_BYTES = 4 * DRAW_COMMAND_WORDS
_DISPATCH_OFFSET = _DRAW_BYTES * len(LISTS)
#: The most work groups a row of a dispatch gets: every GL 4.3 device allows 65535 a side.
MAX_GROUPS = 65535


def _dispatch_shape(length, max_groups=MAX_GROUPS):
    """``(groups per row, rows)`` dispatching `length` blocks: the fewest rows, filled evenly
    (``finish_block_lists.comp`` says why)."""
    rows = max(-(-length // max_groups), 1)
    return -(-length // rows), rows if length else 0


def _commands(counts, blocks, max_groups=MAX_GROUPS):
    """The commands buffer of lists of these lengths holding so many blocks, as
    ``compact_blocks.comp`` and ``finish_block_lists.comp`` make it (``block_lists.glsl``)."""
    draws = [[6, counts[name], 0, 0, 0] for name in LISTS]
    dispatches = [list(_dispatch_shape(counts[name], max_groups)) + [1] for name in LISTS]
    words = [word for command in draws + dispatches + [[blocks[name] for name in LISTS]] for word in command]
    return struct.pack(f"{len(words)}I", *words)


_COMMAND_WORDS = (DRAW_COMMAND_WORDS + DISPATCH_COMMAND_WORDS + 1) * len(LISTS)
# Every list starts empty: 6 vertices (two triangles) per instance, no instances, no groups.
_EMPTY_COMMANDS = _commands(dict.fromkeys(LISTS, 0), dict.fromkeys(LISTS, 0))
#: Above this share of the image's blocks, one triangle over the whole image draws a list
#: faster on a CPU renderer than its runs: the passes on a 2048 x 2048 pair with every
#: block active took 531 ms of CPU with full-screen triangles, 579 ms with runs.
FULL_SCREEN_SHARE = 0.9
# The storage-buffer bindings of the classification shaders.
_COMMANDS, _FLAGS, _FIRST_LIST = 1, 2, 3
# O's block flags, read while the pure colours' blocks are flagged (flag_wakes.comp).
_ORIGINAL_FLAGS = 7
# The compaction's selection of any flag.
_ANY_BITS = 0xFFFFFFFF


def block_grid(size):
    """``(columns, rows)`` of blocks covering an image of ``(width, height)``."""
    return (-(-size[0] // BLOCK_SIDE), -(-size[1] // BLOCK_SIDE))


class BlockLists:
    """The lists of one classified image, as GPU buffers.

    Each list's buffer holds ``(column, row)`` pairs of int32; :attr:`commands` holds the
    indirect commands (GL 4.3), or :attr:`counts` the lengths when the CPU made the lists.
    :attr:`flags` holds a uint32 per block, non-zero where active, when the GPU classified
    them (GL 4.3): the pure colours' blocks are chosen among O's (``flag_wakes.comp``).
    """

    def __init__(self, context, grid):
        self.grid = grid
        capacity = 8 * grid[0] * grid[1]
        self.buffers = {name: context.buffer(reserve=capacity) for name in LISTS}
        self.commands = context.buffer(_EMPTY_COMMANDS)
        self.flags = context.buffer(reserve=4 * grid[0] * grid[1])
        self.counts = None
        self._blocks = None

    def index(self, name):
        return LISTS.index(name)

    def nearly_everything(self, name):
        """Whether list `name` holds more than :data:`FULL_SCREEN_SHARE` of the blocks.

        Reads the counts back from the GPU once per classification: call it only where
        that costs nothing, on a CPU renderer, which has finished the classification anyway.
        """
        if self._blocks is None:
            words = struct.unpack(f"{_COMMAND_WORDS}I", self.commands.read())
            self._blocks = dict(zip(LISTS, words[-len(LISTS):]))
        return self._blocks[name] > FULL_SCREEN_SHARE * self.grid[0] * self.grid[1]

    def reset(self):
        """Forget the counts read back: the lists are being made again."""
        self._blocks = None

    def draw(self, vertex_array, name):
        """Draw a quad per block of list `name` (``blocks.vert``)."""
        if self.counts is None:
            vertex_array.render_indirect(self.commands, moderngl.TRIANGLES, count=1, first=self.index(name))
        elif self.counts[name]:
            vertex_array.render(moderngl.TRIANGLES, vertices=6, instances=self.counts[name])

    def dispatch(self, compute_shader, name):
        """Run a work group per block of list `name` (``compute.glsl`` with BLOCK_LIST)."""
        self.buffers[name].bind_to_storage_buffer(0)
        self.commands.bind_to_storage_buffer(1)
        compute_shader["block_set"] = self.index(name)
        compute_shader.run_indirect(self.commands, offset=_DISPATCH_OFFSET + 4 * DISPATCH_COMMAND_WORDS * self.index(name))

    def release(self):
        for buffer in self.buffers.values():
            buffer.release()
        self.commands.release()
        self.flags.release()


class BlockClassifier:
    """Classifies uploaded images into :class:`BlockLists`, on the GPU.

    Parameters
    ----------
    context : moderngl.Context
    compute : bool
        Whether the context has compute shaders (GL 4.3).
    runs : bool
        List runs of blocks along rows (for drawing, the fragment path) instead of blocks
        (for dispatching, the compute path).
    """

    def __init__(self, context, compute, runs):
        self.context = context
        self.compute = compute
        self.runs = runs
        self._programs = {}
        self._mask_targets = {}
        #: Work groups per row of a dispatch; lists longer than this dispatch several rows.
        self.max_groups = MAX_GROUPS

    def _compute_shader(self, name, defines=None):
        defines = {"MAX_GROUPS": self.max_groups, "RUNS": int(self.runs), **(defines or {})}
        key = (name, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = self.context.compute_shader(load_source(name, defines))
        return self._programs[key]

    def classify(self, texture, lists):
        """Fill `lists` (made for this texture's size) with the blocks of `texture`.

        Parameters
        ----------
        texture : moderngl.Texture
            An image as uploaded; its swizzle gives every layout as RGBA.
        lists : BlockLists
        """
        if self.compute:
            self._classify_with_compute(texture, lists)
        else:
            self._classify_with_fragments(texture, lists)

    @staticmethod
    def _bind(lists, flags):
        """`lists` emptied, and bound with `flags` for a pass that flags blocks and the compaction."""
        lists.reset()
        lists.commands.write(_EMPTY_COMMANDS)
        flags.bind_to_storage_buffer(_FLAGS)
        lists.commands.bind_to_storage_buffer(_COMMANDS)
        for offset, name in enumerate(LISTS):
            lists.buffers[name].bind_to_storage_buffer(_FIRST_LIST + offset)

    def _classify_with_compute(self, texture, lists):
        columns, rows = lists.grid
        lists.flags.clear()
        self._bind(lists, lists.flags)
        texture.use(0)
        flag = self._compute_shader("classify_blocks.comp")
        flag["image"] = 0
        flag["image_size"] = texture.size
        flag["block_grid"] = lists.grid
        flag.run(columns, -(-rows // BLOCK_SIDE))
        self._compact(lists)

    def list_flagged(self, flags, lists):
        """Fill `lists` with the blocks a pass flagged in `flags` (GL 4.3; a uint32 per block).

        Its ``"active"`` list holds the flagged blocks, ``"dilated"`` and ``"inactive"`` the
        same as a classification's (``blocks.block_lists``).
        """
        self._bind(lists, flags)
        self._compact(lists)

    def list_near_wakes(self, wakes, original_lists, lists, split, gate=None):
        """Fill `lists` with O's active blocks (`original_lists`, classified on the GPU) that
        hold a pixel of `wakes` or lie within the margin of one in another of O's active
        blocks (``flag_wakes.comp``; twin ``blocks.pure_colour_mask``), and `split`, a pair of
        lists, with those of them where a ridge could be extended (a ridge's wake that near,
        and with `gate` the gate open on one of the block's pixels) and the others.

        Parameters
        ----------
        wakes : moderngl.Texture
            The wake bits (over 255) of each pixel of O's active blocks.
        original_lists, lists : BlockLists
        split : tuple of two BlockLists
        gate : moderngl.Texture, optional
            The local plan's factor, its gate of drawn content in the second channel.
        """
        # The marks of a compute pass are fetched here; a fragment pass's need no barrier.
        self.context.memory_barrier(moderngl.TEXTURE_FETCH_BARRIER_BIT)
        self._bind(lists, lists.flags)
        original_lists.flags.bind_to_storage_buffer(_ORIGINAL_FLAGS)
        wakes.use(0)
        flag = self._compute_shader("flag_wakes.comp", {"PURE_GATE": int(gate is not None)})
        flag["wakes"] = 0
        if gate is not None:
            gate.use(1)
            flag["strength_factor"] = 1
        flag["image_size"] = wakes.size
        flag["block_grid"] = lists.grid
        flag.run(-(-lists.grid[0] * lists.grid[1] // 64))
        self._compact(lists)
        for part, want in zip(split, (FIT_WHOLE, FIT_PLAIN)):
            self._bind(part, lists.flags)
            self._compact(part, want)

    def _compact(self, lists, want=None):
        """Steps 2 and 3 on the flags bound: the lists and their commands, of the blocks whose
        flags hold a bit of `want` (any)."""
        self.context.memory_barrier(moderngl.SHADER_STORAGE_BARRIER_BIT)
        columns, rows = lists.grid
        compact = self._compute_shader("compact_blocks.comp")
        compact["block_grid"] = lists.grid
        compact["want_bits"] = _ANY_BITS if want is None else want
        compact.run(-(-columns * rows // 64))
        self.context.memory_barrier(moderngl.SHADER_STORAGE_BARRIER_BIT)
        self._compute_shader("finish_block_lists.comp").run(1)
        self.context.memory_barrier(moderngl.COMMAND_BARRIER_BIT | moderngl.VERTEX_ATTRIB_ARRAY_BARRIER_BIT
                                    | moderngl.SHADER_STORAGE_BARRIER_BIT)

    def _classify_with_fragments(self, texture, lists):
        grid = lists.grid
        if grid not in self._mask_targets:
            mask = self.context.texture(grid, 1, dtype="f1")
            self._mask_targets[grid] = (mask, self.context.framebuffer([mask]))
        mask, framebuffer = self._mask_targets[grid]
        if "classify_blocks.frag" not in self._programs:
            program = self.context.program(vertex_shader=load_source("fullscreen.vert"),
                                           fragment_shader=load_source("classify_blocks.frag"))
            self._programs["classify_blocks.frag"] = (program, self.context.vertex_array(program, []))
        program, vertex_array = self._programs["classify_blocks.frag"]
        texture.use(0)
        program["image"] = 0
        framebuffer.use()
        vertex_array.render(moderngl.TRIANGLES, vertices=3)
        flags = np.frombuffer(framebuffer.read(components=1), np.uint8).reshape(grid[1], grid[0])
        listed = block_lists(flags != 0, runs=self.runs)
        for name in LISTS:
            if len(listed[name]):
                lists.buffers[name].write(listed[name].tobytes())
        lists.counts = {name: len(listed[name]) for name in LISTS}
        # A run entry holds (length - 1) << 16 beside its column.
        blocks = {name: int(((entries[:, 0] >> 16) + 1).sum()) if self.runs else len(entries)
                  for name, entries in listed.items()}
        lists.reset()
        lists.commands.write(_commands(lists.counts, blocks, self.max_groups))

    def release(self):
        for program in self._programs.values():
            if isinstance(program, tuple):
                program[1].release()
                program = program[0]
            program.release()
        for mask, framebuffer in self._mask_targets.values():
            framebuffer.release()
            mask.release()
        self._programs, self._mask_targets = {}, {}
