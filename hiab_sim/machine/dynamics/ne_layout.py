"""What the Newton-Euler solve of a machine needs that no design changes: its tree as index arrays.

Built once per :class:`~hiab_sim.machine.description.Machine` object (:func:`layout_of`) from
:func:`hiab_sim.machine.dynamics.tree.machine_tree` and
:func:`hiab_sim.machine.dynamics.planar.planar_bodies`; the solve itself is in
:mod:`hiab_sim.machine.dynamics.ne_kernel`, the design-dependent numbers in
:mod:`hiab_sim.machine.dynamics.ne_design`.

* The tree's order (parents first), which joints are hinges, which bodies carry inertia.
* The chains' closure as groups of like chains (triangles, four-bars), vectorised over chains.
* The pin-force system of :mod:`hiab_sim.machine.dynamics.newton_euler` in block-triangular
  order: each hinge equation involves the loop pins with exactly one of their two bodies in the
  hinge's subtree (a pin with both inside is internal to the subtree: its forces cancel); pins
  that two hinge equations alone determine form 2 x 2 blocks, solved in closed form, level by
  level (one level's blocks do not depend on each other); whatever remains is one dense block.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.planar import PlanarBody, planar_bodies
from hiab_sim.machine.dynamics.tree import MachineTree, PinLayout, actuator_lengths, machine_tree, pin_layout

Complex = NDArray[np.complex128]
Index = NDArray[np.intp]


def _index(values: list[int] | tuple[int, ...]) -> Index:
    return np.asarray(values, dtype=np.intp).reshape(-1)


@dataclass(frozen=True)
class ChainGroups:
    """Chains by kind, as index arrays (one entry per chain of that kind, file order).

    Triangles: ``tri_chain`` (chain index), ``tri_cyl``, ``tri_rod`` (bodies), ``tri_base``
    (link of the base pivot), ``tri_end`` (link of the end pivot), ``tri_loop`` (its pin).
    Four-bars: ``bar_chain``, ``bar_cyl``, ``bar_rod``, ``bar_rocker``, ``bar_coupler``,
    ``bar_base``, ``bar_j`` (link of the rocker pivot J), ``bar_k`` (link of the coupler pivot K),
    ``bar_loop`` (the coupler pin), ``bar_r1``, ``bar_r2`` [m], ``bar_side`` (+-1), ``bar_names``.
    """

    tri_chain: Index
    tri_cyl: Index
    tri_rod: Index
    tri_base: Index
    tri_end: Index
    tri_loop: Index
    bar_chain: Index
    bar_cyl: Index
    bar_rod: Index
    bar_rocker: Index
    bar_coupler: Index
    bar_base: Index
    bar_j: Index
    bar_k: Index
    bar_loop: Index
    bar_r1: Array
    bar_r2: Array
    bar_side: Array
    bar_names: tuple[str, ...]


def chain_groups(tree: MachineTree) -> ChainGroups:
    """Triangle and four-bar chains of the tree (direct chains need no closure)."""
    tri: list[list[int]] = [[], [], [], [], [], []]
    bar: list[list[int]] = [[] for _ in range(9)]
    r1, r2, side, names = [], [], [], []
    for c, chain in enumerate(tree.machine.chains):
        if chain.kind == "direct":
            continue
        cyl = tree.index(f"{chain.name}.cylinder")
        base = tree.bodies[cyl].parent
        if chain.kind == "triangle":
            loop = next(k for k, p in enumerate(tree.loops) if p.body_a == cyl + 1)
            for column, value in zip(tri, (c, cyl, cyl + 1, base, tree.loops[loop].body_b, loop), strict=True):
                column.append(value)
            continue
        linkage = chain.linkage
        if linkage is None:
            raise AssertionError("a linkage chain carries its four-bar")
        rocker = cyl + 2
        loop = next(k for k, p in enumerate(tree.loops) if p.body_a == rocker + 1)
        values = (c, cyl, cyl + 1, rocker, rocker + 1, base, tree.bodies[rocker].parent, tree.loops[loop].body_b, loop)
        for column, value in zip(bar, values, strict=True):
            column.append(value)
        r1.append(linkage.rocker_length)
        r2.append(linkage.coupler_length)
        side.append(float(linkage.pin_side))
        names.append(chain.name)
    t, f = [_index(column) for column in tri], [_index(column) for column in bar]
    return ChainGroups(
        tri_chain=t[0], tri_cyl=t[1], tri_rod=t[2], tri_base=t[3], tri_end=t[4], tri_loop=t[5],
        bar_chain=f[0], bar_cyl=f[1], bar_rod=f[2], bar_rocker=f[3], bar_coupler=f[4], bar_base=f[5],
        bar_j=f[6], bar_k=f[7], bar_loop=f[8],
        bar_r1=np.asarray(r1, dtype=float), bar_r2=np.asarray(r2, dtype=float),
        bar_side=np.asarray(side, dtype=float), bar_names=tuple(names),
    )  # fmt: skip


@dataclass(frozen=True)
class PinSystem:
    """The hinge-moment equations in the loop-pin forces (see the module docstring).

    Entry e couples hinge row ``row[e]`` (body ``hinge[row[e]]``) to pin ``pin[e]`` through the
    pin's point on its body a (``side[e]`` 0) or b (1), body ``side_body[e]``, with sign
    ``sign[e]`` (-1 for a: lambda acts on a with -lambda in the tree's bookkeeping; +1 for b).
    ``levels``: per level, the closed-form 2 x 2 blocks as (pins, first entries, second entries,
    earlier entries and the block slot they feed, as a 0/1 map from those entries to [first row of
    each block, second row]).
    ``dense``: pins and rows left for one dense solve, or None. ``transmit``: (pin, body, sign)
    for every joint whose transmitted force contains the pin's force (not internal to its subtree).
    """

    hinge: Index
    row: Index
    pin: Index
    side: Index
    side_body: Index
    sign: Array
    levels: tuple[tuple[Index, Index, Index, Index, Array], ...]
    dense: tuple[Index, Index] | None
    transmit: tuple[tuple[int, int, float], ...]


def pin_system(tree: MachineTree, below: Array) -> PinSystem:
    """Entries, block order and transmission signs; ``below[j, b]``: body j is in b's subtree."""
    hinges = [b for b, body in enumerate(tree.bodies) if body.kind == "revolute"]
    n_pins = len(tree.loops)
    rows, pins, sides, signs = [], [], [], []
    transmit = np.zeros((n_pins, len(tree.bodies)))
    for b in range(1, len(tree.bodies)):
        for k, loop in enumerate(tree.loops):
            a_in, b_in = bool(below[loop.body_a, b]), bool(below[loop.body_b, b])
            if a_in != b_in:
                transmit[k, b] = -1.0 if a_in else 1.0
    for r, h in enumerate(hinges):
        for k in range(n_pins):
            if transmit[k, h] != 0.0:
                rows.append(r)
                pins.append(k)
                sides.append(0 if transmit[k, h] < 0.0 else 1)
                signs.append(transmit[k, h])
    entries = list(zip(rows, pins, strict=True))
    solved: dict[int, int] = {}  # pin -> level
    used: set[int] = set()
    levels: list[list[tuple[int, int, int]]] = []  # per level: (pin, entry 1, entry 2)
    progress = True
    while progress and len(solved) < n_pins:
        progress = False
        for k in range(n_pins):
            if k in solved:
                continue
            alone = [r for r in range(len(hinges)) if r not in used and _unknowns(entries, r, solved) == {k}]
            if len(alone) < 2:
                continue
            r1, r2 = alone[:2]
            level = 1 + max((solved[p] for rr in (r1, r2) for (q, p) in entries if q == rr and p != k), default=-1)
            while len(levels) <= level:
                levels.append([])
            e1, e2 = entries.index((r1, k)), entries.index((r2, k))
            levels[level].append((k, e1, e2))
            solved[k] = level
            used.update((r1, r2))
            progress = True
    compiled = []
    for blocks in levels:
        own = {e for _, e1, e2 in blocks for e in (e1, e2)}
        slots = [entries[e1][0] for _, e1, _ in blocks] + [entries[e2][0] for _, _, e2 in blocks]
        earlier = [e for e, (r, _) in enumerate(entries) if r in slots and e not in own]
        feed = np.zeros((len(earlier), len(slots)))
        for i, e in enumerate(earlier):
            feed[i, slots.index(entries[e][0])] = 1.0
        compiled.append(
            (
                _index([k for k, _, _ in blocks]),
                _index([e for _, e, _ in blocks]),
                _index([e for _, _, e in blocks]),
                _index(earlier),
                feed,
            )
        )
    left = [k for k in range(n_pins) if k not in solved]
    dense = None
    if left:
        free = [r for r in range(len(hinges)) if r not in used]
        if len(free) != 2 * len(left):
            raise AssertionError("a fully driven tree has one hinge per loop-pin force component")
        dense = (_index(left), _index(free))
    return PinSystem(
        hinge=_index(hinges),
        row=_index(rows),
        pin=_index(pins),
        side=_index(sides),
        side_body=_index(
            [tree.loops[k].body_b if side else tree.loops[k].body_a for k, side in zip(pins, sides, strict=True)]
        ),
        sign=np.asarray(signs, dtype=float),
        levels=tuple(compiled),
        dense=dense,
        transmit=tuple((k, int(b), float(transmit[k, b])) for k in range(n_pins) for b in np.flatnonzero(transmit[k])),
    )


def _unknowns(entries: list[tuple[int, int]], row: int, solved: dict[int, int]) -> set[int]:
    return {k for r, k in entries if r == row and k not in solved}


@dataclass(frozen=True)
class NeConstants:
    """Planar numbers of D designs, each array with D columns (body, pin or chain first).

    ``origin`` (nbody, D) joint origins in the parents' planar frames [m] (complex); ``mass``
    [kg], ``com`` (complex) [m], ``izz`` [kg m^2] (nbody, D) (0 for massless bodies);
    ``point_a``, ``point_b`` (n_pins, D): each loop pin's point on its body a and b [m];
    ``x0`` (n_chains, D): retracted pin-to-pin lengths Lc0 + Lc [m] (0 for a direct chain).
    """

    origin: Complex
    mass: Array
    com: Complex
    izz: Array
    point_a: Complex
    point_b: Complex
    x0: Array

    @property
    def designs(self) -> int:
        """Number of designs D."""
        return int(self.origin.shape[1])


def file_constants(tree: MachineTree, planar: tuple[PlanarBody, ...]) -> NeConstants:
    """The numbers of the machine the tree was built from (D = 1)."""
    x0 = [0.0 if c.kind == "direct" else sum(actuator_lengths(c)) for c in tree.machine.chains]
    return NeConstants(
        origin=np.asarray([[p.origin] for p in planar], dtype=complex),
        mass=np.asarray([[p.mass] for p in planar], dtype=float),
        com=np.asarray([[p.com] for p in planar], dtype=complex),
        izz=np.asarray([[p.inertia_zz] for p in planar], dtype=float),
        point_a=np.asarray([[planar[k.body_a].point(k.point_a)] for k in tree.loops], dtype=complex).reshape(-1, 1),
        point_b=np.asarray([[planar[k.body_b].point(k.point_b)] for k in tree.loops], dtype=complex).reshape(-1, 1),
        x0=np.asarray([[v] for v in x0], dtype=float).reshape(-1, 1),
    )


@dataclass(frozen=True)
class NeLayout:
    """Everything design-independent of the Newton-Euler solve of one machine (see the module docstring).

    ``parent``, ``revolute`` and ``unturn`` e^{-i offset} per body; ``n_links``: the machine's links
    are bodies 0 .. n_links - 1 (no link hangs on a chain body); ``accumulate``: (body, parent) tip
    to base, root excluded; ``below`` (nbody, nbody) 0/1, ``below[j, b]``: body j is in body b's
    subtree; ``axis`` (nbody,) unit slide directions (0 for hinges) and ``offset`` (nbody,) [rad]
    of :class:`PlanarBody`; ``fixed`` (nbody, 3, 3); ``massive``/``massless``: bodies with inertia
    and the rest (the root included); ``actuated`` and ``act_parent``: actuated bodies and their
    parents; ``pins_on``: the body each reported force acts on (:func:`pin_layout` order); joint
    ranges ``low``, ``high`` of the independent joints;
    ``file``: the planar numbers of the machine itself (its design); ``memo``: what other modules
    derive from the layout once (kept here, so it goes with the layout).
    """

    tree: MachineTree
    planar: tuple[PlanarBody, ...]
    parent: tuple[int, ...]
    revolute: tuple[bool, ...]
    unturn: Complex
    n_links: int
    accumulate: tuple[tuple[int, int], ...]
    below: Array
    groups: ChainGroups
    system: PinSystem
    axis: Complex
    offset: Array
    fixed: Array
    massive: Index
    massless: Index
    independent: Index
    actuated: Index
    act_parent: Index
    tcp_point: complex
    pins: PinLayout
    pins_on: Index
    low: Array
    high: Array
    file: NeConstants
    memo: dict[str, object] = field(default_factory=dict, compare=False, repr=False)

    @property
    def n_bodies(self) -> int:
        """Number of tree bodies, root included."""
        return len(self.tree.bodies)


def build_layout(machine: Machine) -> NeLayout:
    """The layout of a machine (uncached; see :func:`layout_of`)."""
    tree = machine_tree(machine)
    planar = planar_bodies(tree)
    n, n_links = len(tree.bodies), len(machine.links)
    below = np.zeros((n, n))
    for j in range(n):
        b = j
        while b >= 0:
            below[j, b] = 1.0
            b = tree.bodies[b].parent
    ranges = [machine.joint_link(name).joint_range for name in machine.joint_names]
    names, kinds, on, by = pin_layout(tree)
    on_index = [*range(1, n), *(loop.body_a for loop in tree.loops)]
    tcp_body = planar[tree.tcp_body]
    return NeLayout(
        tree=tree,
        planar=planar,
        parent=tuple(body.parent for body in tree.bodies),
        revolute=tuple(body.kind == "revolute" for body in tree.bodies),
        unturn=np.exp(-1j * np.asarray([p.offset for p in planar], dtype=float)),
        n_links=n_links,
        accumulate=tuple((b, tree.bodies[b].parent) for b in range(n - 1, 0, -1) if tree.bodies[b].parent > 0),
        below=below,
        groups=chain_groups(tree),
        system=pin_system(tree, below),
        axis=np.asarray([p.axis for p in planar], dtype=complex),
        offset=np.asarray([p.offset for p in planar], dtype=float),
        fixed=np.stack([p.fixed for p in planar]),
        massive=_index([b for b in range(1, n) if tree.bodies[b].inertia is not None]),
        massless=_index([b for b in range(n) if b == 0 or tree.bodies[b].inertia is None]),
        independent=_index(tree.independent),
        actuated=_index(tree.actuated),
        act_parent=_index([tree.bodies[b].parent for b in tree.actuated]),
        tcp_point=tcp_body.point(np.asarray(tree.tcp.position)),
        pins=(names, kinds, on, by),
        pins_on=_index(on_index),
        low=np.array([r[0] for r in ranges if r is not None], dtype=np.float64),
        high=np.array([r[1] for r in ranges if r is not None], dtype=np.float64),
        file=file_constants(tree, planar),
    )


#: Layouts of the machines used last, by object identity (each entry holds its machine, so the id stays its own).
_LAYOUTS: OrderedDict[int, tuple[Machine, NeLayout]] = OrderedDict()
_CACHED = 16  # machines kept; a study uses one or two (its machine, perhaps the crane's converted one)


def layout_of(machine: Machine) -> NeLayout:
    """The layout of ``machine``, built once per machine object (machines are immutable)."""
    key = id(machine)
    entry = _LAYOUTS.get(key)
    if entry is not None and entry[0] is machine:
        _LAYOUTS.move_to_end(key)
        return entry[1]
    layout = build_layout(machine)
    _LAYOUTS[key] = (machine, layout)
    while len(_LAYOUTS) > _CACHED:
        _LAYOUTS.popitem(last=False)
    return layout
