"""Which elements the element stage takes in blocks (kernels.shell_blocks), built once per
Workspace: the plan of blocks, their static geometry in block layout, and the threads'
scratch rows (docs/theory.md §4.6, "SIMD element pass").

An element goes into a block when its section is the default fabric section — a 2×2
membrane with one point through the thickness, and its material the crossover model with
the tabulated crossover, the fibre frame, the true trellis law and the virial resultant —
or an elastic resultant section with the one-point membrane (the default for an elastic
material). A block holds elements of one section; the last block of each section repeats
its last element into the lanes it does not use (computed, never written). Every other
element (J2 metal, the blade, fabric with other options) stays with ``shell_force``.

``WOVENIMPACT_BLOCKS=0`` in the environment keeps every element with ``shell_force`` (the
results are bitwise the same; for measuring the two against each other).
"""

from __future__ import annotations

import os

import numba
import numpy as np

from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_blocks as SB
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.bundles import BlockPlan, BlockScratch

LANES = SB.LANES


def blocks_enabled() -> bool:
    """False when ``WOVENIMPACT_BLOCKS`` is set to 0."""
    return os.environ.get("WOVENIMPACT_BLOCKS", "1").strip() != "0"


def block_sections(model) -> list[int]:
    """The sections whose elements the block stage can take (the module docstring)."""
    fabric_rows = model.point_width > 0  # (a 2×2 fabric section's element owns 4 rows)
    out = []
    for s, row in enumerate(model.sections):
        m = int(row[SL.C_MAT])
        p = model.mat_params[m]
        if (model.mat_kind[m] == SL.MAT_ELASTIC and int(row[SL.C_POINTS]) == 1
                and int(row[SL.C_INPLANE]) == SL.MEMBRANE_REDUCED):
            out.append(s)
        elif (fabric_rows and model.mat_kind[m] == SL.MAT_FABRIC
                and int(row[SL.C_POINTS]) == 1
                and int(row[SL.C_INPLANE]) == SL.MEMBRANE_FULL
                and p[FL.P_CROSSOVER] == FL.CROSSOVER_TABLE and p[FL.P_TAB_NW] >= 2
                and p[FL.P_TAB_NF] >= 2 and p[FL.P_FRAME] == FL.FRAME_FIBRE
                and p[FL.P_SHEAR] == FL.SHEAR_TRUE and p[FL.P_HOMOG] == FL.HOMOG_VIRIAL):
            out.append(s)
    return out


def _to_blocks(values: np.ndarray, elems: np.ndarray) -> np.ndarray:
    """(n_elems, width) per-element values → the flat block layout of ``elems`` (lanes of
    consecutive blocks): value k of lane l of block b at (b · width + k) · LANES + l."""
    v = values.reshape(values.shape[0], -1)[elems]  # (n_blocks · LANES, width)
    nb, width = elems.size // LANES, v.shape[1]
    return np.ascontiguousarray(v.reshape(nb, LANES, width).transpose(0, 2, 1)).ravel()


def block_plan(model) -> BlockPlan | None:
    """The plan for ``model`` (None when no element qualifies or blocks are disabled)."""
    if not blocks_enabled():
        return None
    secs = block_sections(model)
    if not secs:
        return None
    elems, lanes, section = [], [], []
    for s in secs:
        ids = np.flatnonzero(model.elem_section == s)
        for start in range(0, ids.size, LANES):
            chunk = ids[start:start + LANES]
            lanes.append(chunk.size)
            section.append(s)
            elems.append(np.concatenate([chunk, np.full(LANES - chunk.size, chunk[-1])]))
    elems = np.concatenate(elems).astype(np.int64)
    taken = np.zeros(model.n_elems, dtype=bool)
    taken[elems] = True
    return BlockPlan(
        elems=elems, lanes=np.array(lanes, dtype=np.int64),
        section=np.array(section, dtype=np.int64),
        others=np.flatnonzero(~taken).astype(np.int64),
        gauss_grad=_to_blocks(model.gauss_grad, elems),
        gauss_weight=_to_blocks(model.gauss_weight, elems),
        ref_grad=_to_blocks(model.ref_grad, elems),
        area0=_to_blocks(model.area0[:, None], elems),
        rot_inertia=_to_blocks(model.elem_rot_inertia[:, None], elems),
    )


def block_scratch(plan: BlockPlan) -> BlockScratch:
    """One scratch row per thread Numba may run (``get_thread_id`` < NUMBA_NUM_THREADS),
    and the plan's lanes' pending bytes."""
    # get_thread_id() is below the size of the thread pool Numba launched, which in a
    # forked pool worker is its parent's (NUMBA_NUM_THREADS is then the worker's own);
    # the kernel sends a block whose thread has no row to shell_force all the same
    t = max(numba.config.NUMBA_NUM_THREADS, numba.get_num_threads(), os.cpu_count() or 1)

    def rows(values: int) -> np.ndarray:
        # each thread's row padded by 16 doubles (two cache lines): threads writing
        # neighbouring rows would otherwise share a line
        return np.zeros((t, values * LANES + 16))

    return BlockScratch(
        corners=rows(SB.N_CORNER), old=rows(SB.N_OLD), kin=rows(4 * SB.N_KIN),
        coef=rows(4 * SB.N_COEF), geo=rows(4 * SB.N_GEO), flag=rows(1), exact=rows(4),
        res=rows(4 * SB.N_RES), out_el=rows(SB.N_OUT_EL), out_blk=rows(SB.N_BLK),
        pending=np.zeros(plan.elems.size, dtype=np.int8))
