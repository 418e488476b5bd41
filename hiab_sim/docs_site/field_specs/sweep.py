"""The sweep file's keys (:func:`hiab_sim.sweep.spec.load_sweep`), written next to its reader's name."""

from __future__ import annotations

from hiab_sim.docs_site.field_specs.rows import Key, free, section, text


def sweep_keys() -> list[Key]:
    """The sweep file (:func:`hiab_sim.sweep.spec.load_sweep`)."""
    return [
        text("name", "Sweep name.", default="the file's stem"),
        text("study", "Shipped study name or a study path relative to the sweep file."),
        free("set", "Dotted paths into the study (or `emla.` into its EMLA file) set at every point.", "path: value"),
        free(
            "grid",
            "Full factorial over axes: `path: [values]`, or a zipped axis `{values?, path: [..], ...}`.",
            "path: list",
        ),
        section("sample", "A seeded Latin-hypercube sample instead of a grid.", "none"),
        Key("sample.points", type="integer", allowed=">= 1", description="Number of points."),
        Key("sample.seed", type="integer", default="0", description="Seed of `scipy.stats.qmc.LatinHypercube`."),
        free("sample.ranges", "`path: [low, high]` per sampled path.", "path: [number, number]"),
    ]
