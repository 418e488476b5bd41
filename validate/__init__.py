"""Validation cases; the wheel carries this folder as ``hiab_sim._data.validate`` (see hiab_sim/resources.py)."""
