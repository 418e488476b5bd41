"""The validation cases file's keys (:func:`hiab_sim.validation.load_cases`), from its dataclasses."""

from __future__ import annotations

from hiab_sim.docs_site.field_specs.rows import Key, from_class, section, text


def cases_keys() -> list[Key]:
    """The validation cases file (:func:`hiab_sim.validation.load_cases`)."""
    from hiab_sim.validation import CaseSpec, Tolerances

    return [
        section("tolerances", "Pass thresholds of `hiab-sim validate`.", "defaults"),
        *from_class(
            "tolerances",
            Tolerances,
            force_relative={"description": "Force error over each actuator's peak |f| in the case."},
            velocity_absolute={"description": "Velocity error."},
            balance_relative={"description": "Power balance or virtual work of the analytic path, relative."},
        ),
        Key(
            "payload_force",
            type="[number, number, number]",
            unit="N",
            default="[0, -2452, 0]",
            description="TCP force in {W} of the payload cases (a 250 kg payload).",
        ),
        Key("cases", type="list", description="The cases."),
        section("cases[]", "One case."),
        *from_class(
            "cases[]",
            CaseSpec,
            skip=("payload",),
            name={"description": "Case name (`+payload` is appended for the payload copy)."},
            kind={"description": "What the case samples."},
            samples={"description": "Joint samples (`--samples` overrides)."},
            seed={"description": "Random seed."},
            length_sets={"description": "Random link-length sets (random_lengths)."},
            description={"description": "Shown in the table."},
        ),
        text(
            "cases[].payload",
            "Run without, with, or without and with the payload force.",
            default="both",
            allowed="one of `none`, `payload`, `both`",
        ),
    ]
