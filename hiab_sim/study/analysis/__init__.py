"""Analyses of an optimum: sensitivities, buildable designs, cross-evaluation, co-design, comparisons."""
