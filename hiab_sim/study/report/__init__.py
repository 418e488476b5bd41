"""The result folder's sections built from an optimum: designs, energy, solver, buildable, analyses."""
