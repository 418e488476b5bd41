"""Shipped studies and their crane and EMLA files; the wheel carries this folder as ``hiab_sim._data.studies``.

Load them by name (``hiab-sim optimize xs031_spiral``) or by path; see hiab_sim/resources.py.
"""
