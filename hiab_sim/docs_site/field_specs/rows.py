"""Documented-key rows: :class:`Key` and the helpers that build rows from sections, free mappings and dataclasses.

Where a reader builds a dataclass from a section (:func:`hiab_sim.yaml_fields.section` and its kin),
:func:`from_class` takes the rows from that dataclass
(:func:`~hiab_sim.docs_site.dataclass_fields.field_rows`: its type, default, the docstring's
description and unit, the range its ``__post_init__`` checks).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from hiab_sim.docs_site.dataclass_fields import field_rows

SOURCED = "number or {value, source}"


@dataclass(frozen=True)
class Key:
    """One documented key: dotted path (grammar of :mod:`hiab_sim.docs_site.probe`), kind and its facts."""

    path: str
    #: "value", "section" (a mapping of the keys below it), "free" (any key) or "names" (keys the loader
    #: takes from another file, e.g. a machine's decision variables: checked, but not listed here)
    kind: str = "value"
    type: str = ""
    unit: str = ""
    default: str = ""
    allowed: str = ""
    description: str = ""
    #: The form of the file the key belongs to (:class:`hiab_sim.docs_site.formats.Form`); "" every form.
    form: str = ""


def number(path: str, unit: str, description: str, *, allowed: str = "", default: str = "", form: str = "") -> Key:
    """A number in ``unit`` (``""``: none), with the range it must lie in and its default where they are stated."""
    return Key(path, type="number", unit=unit, default=default, allowed=allowed, description=description, form=form)


def interval(path: str, unit: str, description: str, *, allowed: str = "") -> Key:
    """A ``[low, high]`` pair of numbers in ``unit``, with the range it must lie in where one is stated."""
    return Key(path, type="[number, number]", unit=unit, allowed=allowed, description=description)


def text(path: str, description: str, *, default: str = "", allowed: str = "", form: str = "") -> Key:
    """A text value (a name, a path or one of the words ``allowed`` lists), with its default where one is stated."""
    return Key(path, type="text", default=default, allowed=allowed, description=description, form=form)


def section(path: str, description: str, default: str = "required") -> Key:
    """A mapping whose keys are documented by the rows below it."""
    return Key(path, "section", "mapping", default=default, description=description)


def free(path: str, description: str, type_: str = "") -> Key:
    """A mapping whose keys are names or dotted paths chosen by the user."""
    return Key(path, "free", type_, description=description)


def names(path: str, description: str, type_: str = "", form: str = "", default: str = "") -> Key:
    """A mapping whose keys are names another file defines (the loader checks them against that file)."""
    return Key(path, "names", type_, default=default, description=description, form=form)


def in_form(form: str, keys: list[Key]) -> list[Key]:
    """``keys`` marked as belonging to the file form ``form`` only."""
    return [replace(k, form=form) for k in keys]


def from_class(prefix: str, cls: type, skip: tuple[str, ...] = ("label",), **overrides: dict[str, str]) -> list[Key]:
    """The rows of dataclass ``cls``'s fields under ``prefix``; ``overrides`` replace facts per field."""
    out = []
    for name, facts in field_rows(cls, skip).items():
        row = {**facts, **overrides.get(name, {})}
        out.append(Key(f"{prefix}.{name}" if prefix else name, "value", **row))
    return out


def sourced(keys: list[Key], required: bool = True) -> list[Key]:
    """Rows of a provenance-carrying section: each value a number or ``{value, source}``."""
    return [
        replace(k, type=SOURCED, default=k.default if not required or k.default != "required" else "required")
        for k in keys
    ]


def under(prefix: str, keys: list[Key]) -> list[Key]:
    """``keys`` moved under the mapping ``prefix`` (``a`` -> ``prefix.a``)."""
    return [replace(k, path=f"{prefix}.{k.path}") for k in keys]


def section_of(
    path: str, description: str, keys: list[Key], default: str = "required", *, keys_default: str | None = None
) -> list[Key]:
    """A section (:func:`section`, its own ``default``) and its keys moved under it (:func:`under`).

    ``keys_default`` replaces every key's default: an actuator's overrides of a shared section are
    the shared rows with ``keys_default="shared"``.
    """
    rows = under(path, keys)
    if keys_default is not None:
        rows = [replace(k, default=keys_default) for k in rows]
    return [section(path, description, default), *rows]
