"""Shipped data folders, mapped from the repository's top level by pyproject.toml (read through hiab_sim.resources).

``hiab_sim._data.mjcf`` is ``assets/mjcf/``, ``hiab_sim._data.studies`` is ``optimize/`` and
``hiab_sim._data.validate`` is ``validate/``: users read and copy those folders in the source tree,
and the built wheel carries them under this package.
"""
