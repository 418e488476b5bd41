"""Shared MJCF pieces; the wheel carries this folder as ``hiab_sim._data.mjcf`` (see hiab_sim/resources.py)."""
